# Two commands set everything up on a fresh Debian 12 machine (as root):
#   make demo   install dependencies, build, run the demo
#   make test   install dependencies, build, run every test
# Catkin runs with Debian's python3, which has catkin_pkg.
SHELL := /bin/bash
.SHELLFLAGS := -eo pipefail -c
export PATH := /usr/bin:/bin:/usr/sbin:/sbin:$(PATH)

ROOT := $(abspath .)
WS := $(ROOT)/.ws
CORE_BUILD := $(ROOT)/build/sanitize
JOBS ?= 2
CMAKE_ARGS ?=
CATKIN := catkin_make -C $(WS) -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo $(CMAKE_ARGS)

.PHONY: demo test deps build test-sanitize bench clean format

demo: build
	@echo "[demo] dropping a few bodies"
	$(WS)/devel/lib/rigid_body_sim/drop_demo

test: build
	@echo "[test] building the tests"
	$(CATKIN) tests -j$(JOBS) 2>&1 | (grep --line-buffered -E '^\[ *[0-9]+%\]|error|warning' || true)
	@echo "[test] running every test"
	cd $(WS)/build && ctest --output-on-failure

deps:
	@bash scripts/install_deps.sh

$(WS)/src/rigid_body_sim:
	mkdir -p $(WS)/src
	ln -sfn $(ROOT) $(WS)/src/rigid_body_sim

build: deps $(WS)/src/rigid_body_sim
	@echo "[build] catkin_make in $(WS)"
	$(CATKIN) -j$(JOBS) 2>&1 | (grep --line-buffered -vE '^-- (Found|Looking|Detecting|Check|Performing|Using)' || true)

# The ROS-free libraries and their gtests under AddressSanitizer and
# UndefinedBehaviorSanitizer, built with plain CMake.
test-sanitize: deps
	cmake -S $(ROOT) -B $(CORE_BUILD) -DRBS_CORE_ONLY=ON -DRBS_WERROR=ON -DCMAKE_BUILD_TYPE=Debug \
	  -DCMAKE_CXX_FLAGS="-O1 -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer" \
	  > /dev/null
	cmake --build $(CORE_BUILD) -j$(JOBS)
	cd $(CORE_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --output-on-failure

clean:
	rm -rf $(WS) $(ROOT)/build

format:
	clang-format -i $$(git ls-files '*.h' '*.cc')
