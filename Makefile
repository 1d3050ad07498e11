# Two commands set everything up on a fresh Debian 12 machine (as root):
#   make demo   install dependencies, build, run the demo
#   make test   install dependencies, build, run every test
# Catkin runs with Debian's python3, which has catkin_pkg.
SHELL := /bin/bash
.SHELLFLAGS := -eo pipefail -c
export PATH := /usr/bin:/bin:/usr/sbin:/sbin:$(PATH)

ROOT := $(abspath .)
# The catkin workspaces live in hidden directories under build/: rosrun does
# not search a package's build/, and roslaunch's and rostest's search skips
# hidden directories, so neither follows the workspace's link back to the
# repository nor finds an executable twice.
WS := $(ROOT)/build/.ws
CORE_BUILD := $(ROOT)/build/sanitize
JOBS ?= 2
CMAKE_ARGS ?=
# Line tables only (-g1): stack traces, sanitizer reports and perf keep
# their file:line, and the builds take about a third less time than with
# full debug information (the core: 2.4 min instead of 3.4 min on 2 cores).
# `make test DEBUG_INFO=-g` brings back gdb's locals.
DEBUG_INFO := -g1
RELWITHDEBINFO := -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 $(DEBUG_INFO) -DNDEBUG"
CATKIN := catkin_make -C $(WS) -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  $(RELWITHDEBINFO) $(CMAKE_ARGS)

.PHONY: demo test deps build test-sanitize sanitize test-tsan fuzz bench clean format soak

# The demo scene without rviz for DEMO_SECONDS of real time, showing the
# node's log (its status line comes every 5 s). Succeeds when the node
# logged at least one status line.
# DEMO_LAUNCH=drive_demo.launch runs the drive demo instead.
DEMO_SECONDS ?= 20
DEMO_LAUNCH ?= demo.launch
demo: build
	@echo "[demo] roslaunch rigid_body_sim $(DEMO_LAUNCH) for $(DEMO_SECONDS) s (rviz:=true adds rviz)"
	@set +e; source $(WS)/devel/setup.bash; \
	  timeout --signal=INT --kill-after=10 $(DEMO_SECONDS) roslaunch rigid_body_sim $(DEMO_LAUNCH) 2>&1 \
	  | sed -u 's/\x1b\[[0-9;]*m//g' | grep --line-buffered -E '^\[ *(INFO|WARN|ERROR|FATAL)\]' \
	  | tee $(WS)/demo.log; \
	  grep -q 'sim time' $(WS)/demo.log

test: build
	@echo "[test] building the tests"
	$(CATKIN) tests -j$(JOBS) 2>&1 | (grep --line-buffered -E '^\[ *[0-9]+%\]|[Ee]rror|warning|undefined' || true)
	@echo "[test] running every test"
	cd $(WS)/build && ctest --output-on-failure

deps:
	@bash scripts/install_deps.sh

# The package in the workspace: a directory of links to the repository's
# top-level entries, all but build/, so that nothing that follows links
# (find -L, rosrun, rospack) walks from the workspace back into itself.
# Refreshed on every build, so a new top-level entry is linked too.
.PHONY: ws-links
ws-links:
	@if [ -L $(WS)/src/rigid_body_sim ]; then rm $(WS)/src/rigid_body_sim; fi
	@mkdir -p $(WS)/src/rigid_body_sim
	@for entry in $(ROOT)/* $(ROOT)/.clang-format; do \
	  name=$$(basename $$entry); \
	  [ "$$name" = build ] || ln -sfn $$entry $(WS)/src/rigid_body_sim/$$name; \
	done
	@find $(WS)/src/rigid_body_sim -maxdepth 1 -xtype l -delete
	@# catkin writes the environment ctest runs the tests in when it first
	@# configures, and puts only directories that exist then on PYTHONPATH:
	@# without this one, a fresh clone's Python tests cannot import the
	@# package's generated messages.
	@mkdir -p $(WS)/devel/lib/python3/dist-packages

build: deps ws-links
	@echo "[build] catkin_make in $(WS)"
	$(CATKIN) -j$(JOBS) 2>&1 | (grep --line-buffered -vE '^-- (Found|Looking|Detecting|Check|Performing|Using)' || true)

# The ROS-free libraries and their gtests under AddressSanitizer and
# UndefinedBehaviorSanitizer, built with plain CMake. Our asserts stay on;
# Eigen's per-coefficient range checks are off, or the 1,000-box pile takes
# most of an hour. GCC 12's
# maybe-uninitialized analysis gives false positives on instrumented code
# (std::variant holding a shared_ptr), so that one warning is off here; the
# -Werror build is `make test`'s.
test-sanitize: deps
	cmake -S $(ROOT) -B $(CORE_BUILD) -DRBS_CORE_ONLY=ON -DRBS_WERROR=ON -DCMAKE_BUILD_TYPE=None \
	  -DCMAKE_CXX_FLAGS="-O2 $(DEBUG_INFO) -DEIGEN_NO_DEBUG -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer -Wno-maybe-uninitialized" \
	  > /dev/null
	cmake --build $(CORE_BUILD) -j$(JOBS)
	cd $(CORE_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --output-on-failure

# The concurrency rostest with the node and its client built under
# ThreadSanitizer in a second workspace; any report fails the target.
WS_TSAN := $(ROOT)/build/.ws-tsan
test-tsan: deps
	$(MAKE) --no-print-directory ws-links WS=$(WS_TSAN)
	catkin_make -C $(WS_TSAN) -DPYTHON_EXECUTABLE=/usr/bin/python3 $(RELWITHDEBINFO) \
	  -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" \
	  -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread $(CMAKE_ARGS) \
	  rigid_body_sim_node node_concurrency_test -j$(JOBS) 2>&1 \
	  | (grep --line-buffered -E '^\[ *[0-9]+%\]|[Ee]rror|warning|undefined' || true)
	rm -f $(WS_TSAN)/tsan.*
	source $(WS_TSAN)/devel/setup.bash && \
	  TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$(ROOT)/test/node/tsan.supp log_path=$(WS_TSAN)/tsan" \
	  rostest $(ROOT)/test/node/node_concurrency_test.test
	@if ls $(WS_TSAN)/tsan.* > /dev/null 2>&1; then \
	  cat $(WS_TSAN)/tsan.*; echo "[test-tsan] ThreadSanitizer reported a race" >&2; exit 1; fi
	@echo "[test-tsan] no ThreadSanitizer reports"

# `make sanitize`: every gtest of the ROS-free libraries (rbs_core_tests)
# and every node test, with the libraries, the node, its mesh helper and the
# test clients built once under ASan and UBSan in a workspace of their own
# (asserts on: no NDEBUG; the libraries compiled once for both, which
# test-sanitize's separate build did twice). Python tests drive
# the instrumented node. Any sanitizer report (a leak at exit included) fails
# the target; the reports are in build/.ws-asan/asan.*. Allocations the
# node's limits refuse come back as null instead of an ASan abort
# (allocator_may_return_null), as they would without ASan. node_scale_test
# is left out: it asserts the publish rate with 1,000 boxes, a speed the
# sanitizers' several-fold slowdown does not keep.
WS_ASAN := $(ROOT)/build/.ws-asan
SANITIZE_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
SANITIZE_TARGETS := rigid_body_sim_node rigid_body_sim_mesh_helper rigid_body_sim_generate_messages \
  rigid_body_sim_gencfg rbs_core_tests node_conversion_test \
  node_services_test node_falling_box_test node_contacts_test node_concurrency_test \
  node_hostile_test node_hostile_joints_test node_time_stamps_test
sanitize: deps
	$(MAKE) --no-print-directory ws-links WS=$(WS_ASAN)
	catkin_make -C $(WS_ASAN) -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=None \
	  -DCMAKE_CXX_FLAGS="-O2 $(DEBUG_INFO) $(SANITIZE_FLAGS) -DEIGEN_NO_DEBUG -Wno-maybe-uninitialized" \
	  -DCMAKE_EXE_LINKER_FLAGS="$(SANITIZE_FLAGS)" $(CMAKE_ARGS) \
	  $(SANITIZE_TARGETS) -j$(JOBS) 2>&1 \
	  | (grep --line-buffered -E '^\[ *[0-9]+%\]|[Ee]rror|warning|undefined' || true)
	rm -f $(WS_ASAN)/asan.*
	@# The gtests (one process each, nothing timed) run JOBS at a time; the
	@# rostests one at a time, as each starts a master and a node.
	cd $(WS_ASAN)/build && \
	  export ASAN_OPTIONS="detect_leaks=1 allocator_may_return_null=1 log_path=$(WS_ASAN)/asan" \
	  LSAN_OPTIONS="suppressions=$(ROOT)/test/node/lsan.supp" \
	  UBSAN_OPTIONS="print_stacktrace=1 log_path=$(WS_ASAN)/asan" && \
	  ctest --output-on-failure -R gtest -j$(JOBS) && \
	  ctest --output-on-failure -R rostest -E node_scale
	@if ls $(WS_ASAN)/asan.* > /dev/null 2>&1; then \
	  cat $(WS_ASAN)/asan.*; echo "[sanitize] a sanitizer reported an error" >&2; exit 1; fi
	@echo "[sanitize] no AddressSanitizer or UndefinedBehaviorSanitizer reports"

# libFuzzer harnesses (fuzz/) for the URDF loader, the mesh helper's parsing
# and the node's request validation, built with clang under ASan and UBSan
# in a plain CMake build of the ROS-free code. Each runs FUZZ_SECONDS on a
# scratch copy of its seed corpus (fuzz/corpus/<name>); a crash, leak,
# timeout or out-of-memory fails the target and leaves the input in
# build/fuzz/artifacts.
FUZZ_BUILD := $(ROOT)/build/fuzz
FUZZ_SECONDS ?= 600
FUZZERS := urdf_loader_fuzzer mesh_parser_fuzzer request_validation_fuzzer joint_requests_fuzzer \
  decomposition_cache_fuzzer
fuzz: deps
	cmake -S $(ROOT) -B $(FUZZ_BUILD) -DRBS_CORE_ONLY=ON -DRBS_FUZZ=ON -DCMAKE_BUILD_TYPE=None \
	  -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang \
	  -DCMAKE_CXX_FLAGS="-O1 -gline-tables-only -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all" \
	  > /dev/null
	cmake --build $(FUZZ_BUILD) -j$(JOBS) --target $(FUZZERS) rigid_body_sim_mesh_helper
	@mkdir -p $(FUZZ_BUILD)/artifacts
	@for fuzzer in $(FUZZERS); do \
	  name=$${fuzzer%_fuzzer}; rm -rf $(FUZZ_BUILD)/corpus/$$name; mkdir -p $(FUZZ_BUILD)/corpus/$$name; \
	  cp $(ROOT)/fuzz/corpus/$$name/* $(FUZZ_BUILD)/corpus/$$name/; \
	  echo "[fuzz] $$fuzzer for $(FUZZ_SECONDS) s"; \
	  $(FUZZ_BUILD)/$$fuzzer -max_total_time=$(FUZZ_SECONDS) -timeout=30 -rss_limit_mb=2048 \
	    -max_len=65536 -print_final_stats=1 -artifact_prefix=$(FUZZ_BUILD)/artifacts/$$name- \
	    $(FUZZ_BUILD)/corpus/$$name > $(FUZZ_BUILD)/$$name.log 2>&1 \
	    || { tail -40 $(FUZZ_BUILD)/$$name.log; echo "[fuzz] $$fuzzer failed" >&2; exit 1; }; \
	  grep -E '^stat::number_of_executed_units|^#[0-9]+.*DONE' $(FUZZ_BUILD)/$$name.log | tail -2; \
	done
	@echo "[fuzz] no crash in $(FUZZERS)"

# The benchmark scenes in our engine and side by side in Bullet (only this
# build links Bullet), then the component benchmarks, the plot and the
# table of ratios. A plain CMake Release build of the ROS-free core.
# pile_4000 and pyramid_90 simulate BENCH_SCALE x 10 s so that the run
# stays within minutes.
BENCH_BUILD := $(ROOT)/build/bench
BENCH_SCALE ?= 0.2
BENCH_RUNS ?= 3
# Comma-separated scene names to run only those (physics_bench --only).
BENCH_ONLY ?=
bench: deps
	@# MuJoCo is the benchmark's alone (physics_bench's articulated scenes): not
	@# in install_deps.sh, so that make test and CI do not install it.
	@dpkg -s libmujoco-dev 2> /dev/null | grep -q '^Status: install ok installed' || \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends libmujoco-dev || \
	  { apt-get update -q && DEBIAN_FRONTEND=noninteractive \
	    apt-get install -y -q --no-install-recommends libmujoco-dev; }
	cmake -S $(ROOT) -B $(BENCH_BUILD) -DRBS_CORE_ONLY=ON -DRBS_BENCH=ON -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG" > /dev/null
	cmake --build $(BENCH_BUILD) -j$(JOBS) \
	  --target physics_bench hull_bench narrow_phase_bench broad_phase_bench chain_scaling_bench \
	  ray_bench soft_lanes_bench
	mkdir -p $(ROOT)/bench/results
	@echo "[bench] $$(nproc) cores,$$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2), $$(date -u '+%F %H:%M UTC')"
	$(BENCH_BUILD)/physics_bench --runs $(BENCH_RUNS) --scale $(BENCH_SCALE) \
	  $(if $(BENCH_ONLY),--only $(BENCH_ONLY)) \
	  --csv $(ROOT)/bench/results/latest.csv --hull-bench $(BENCH_BUILD)/hull_bench
	@if [ -x $(WS)/devel/lib/rigid_body_sim/rigid_body_sim_node ]; then \
	  source $(WS)/devel/setup.bash && \
	  python3 $(ROOT)/bench/spawn_bench.py --csv $(ROOT)/bench/results/latest.csv && \
	  python3 $(ROOT)/bench/ray_service_bench.py && \
	  $(CATKIN) ray_service_client -j$(JOBS) > /dev/null && \
	  python3 $(ROOT)/bench/ray_service_bench.py --client $(WS)/devel/lib/rigid_body_sim/ray_service_client; \
	else echo "spawn: node not built ($(WS)/devel/lib/rigid_body_sim/rigid_body_sim_node; make build)"; fi
	$(BENCH_BUILD)/narrow_phase_bench 200000
	$(BENCH_BUILD)/soft_lanes_bench
	$(BENCH_BUILD)/broad_phase_bench 30
	$(BENCH_BUILD)/chain_scaling_bench 480
	$(BENCH_BUILD)/ray_bench 100000
	python3 $(ROOT)/bench/plot.py $(ROOT)/bench/results/latest.csv $(ROOT)/bench/results/ms_per_step.png
	@echo "[bench] ours against Bullet, wall clock and per awake step (bench/ratios.py):"
	@python3 $(ROOT)/bench/ratios.py $(ROOT)/bench/results/latest.csv

# A soak of the node (test/soak/soak.py): spawn, delete, reset, wrench,
# joint and step churn for SOAK_SECONDS on a master of its own; fails on a
# refused well-formed request, a dead node, or RSS growth above 5 % after a
# one-minute warm-up.
SOAK_SECONDS ?= 3600
SOAK_PORT ?= 11397
soak: build
	@set +e; source $(WS)/devel/setup.bash; export ROS_MASTER_URI=http://localhost:$(SOAK_PORT); \
	  roslaunch -p $(SOAK_PORT) rigid_body_sim sim.launch paused:=true > $(WS)/soak_node.log 2>&1 & \
	  launch=$$!; \
	  python3 $(ROOT)/test/soak/soak.py --seconds $(SOAK_SECONDS); status=$$?; \
	  kill -INT $$launch; wait $$launch; \
	  grep -E "\[ERROR\]|\[FATAL\]" $(WS)/soak_node.log && status=1; \
	  exit $$status

clean:
	rm -rf $(WS) $(WS_TSAN) $(WS_ASAN) $(ROOT)/build

format:
	clang-format -i $$(git ls-files '*.h' '*.cc')
