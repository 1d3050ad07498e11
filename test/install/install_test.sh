#!/usr/bin/env bash
# Installs the built catkin workspace into a temporary prefix and runs the
# package from there alone, in a clean environment: rospack finds it in the
# prefix, `roslaunch rigid_body_sim demo.launch` brings up the demo's 19
# models, and the installed spawn_model adds one more from a file given
# relative to the caller's directory. Run by ctest (install_test) with the
# workspace's build directory as its argument.
set -euo pipefail

build_dir=${1:?usage: install_test.sh <catkin build directory>}
prefix=$(mktemp -d /tmp/rbs_install.XXXXXX)
launch_pid=
# roslaunch runs in a session of its own (setsid), so that its master and
# nodes can be stopped together: SIGINT, then SIGKILL after 30 s.
cleanup() {
  if [ -n "$launch_pid" ] && kill -0 "$launch_pid" 2> /dev/null; then
    kill -INT -- "-$launch_pid" 2> /dev/null || true
    for _ in $(seq 150); do kill -0 -- "-$launch_pid" 2> /dev/null || break; sleep 0.2; done
    kill -KILL -- "-$launch_pid" 2> /dev/null || true
  fi
  rm -rf "$prefix"
}
trap cleanup EXIT

echo "[install_test] cmake --install $build_dir --prefix $prefix"
cmake --install "$build_dir" --prefix "$prefix" > "$prefix/install.log"
# catkin installs its setup files to the configured prefix by absolute path,
# which --prefix does not redirect; they are the ones generated for the
# install space, copied as `catkin_make install` would.
for file in setup.sh setup.bash local_setup.sh local_setup.bash _setup_util.py env.sh; do
  cp "$build_dir/catkin_generated/installspace/$file" "$prefix/"
done
# Only catkin's own package.xml may be a link (build/.ws links the sources);
# everything of ours must be copied, or the install space needs the sources.
links=$(cd "$prefix" && find . -type l ! -path ./share/rigid_body_sim/package.xml)
[ -z "$links" ] || { echo "[install_test] links into the source tree: $links" >&2; exit 1; }

for path in lib/rigid_body_sim/rigid_body_sim_node lib/rigid_body_sim/drop_demo \
  lib/rigid_body_sim/spawn_model share/rigid_body_sim/package.xml \
  share/rigid_body_sim/launch/demo.launch share/rigid_body_sim/config/sim.yaml \
  share/rigid_body_sim/urdf/meshes/pebble.stl share/rigid_body_sim/rviz/sim.rviz \
  share/rigid_body_sim/worlds/bin.yaml share/rigid_body_sim/cfg/Physics.cfg; do
  [ -e "$prefix/$path" ] || { echo "[install_test] missing $prefix/$path" >&2; exit 1; }
done

# A free port for the test's own master, so that nothing else is disturbed.
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
caller=$prefix/caller
mkdir -p "$caller/models"
cp "$prefix/share/rigid_body_sim/urdf/box.urdf" "$caller/models/"

# Nothing of the source or devel space: only the install prefix is sourced.
env -i HOME="$prefix" PATH=/usr/bin:/bin LANG=C.UTF-8 \
  ROS_MASTER_URI="http://127.0.0.1:$port" ROS_HOSTNAME=127.0.0.1 ROS_LOG_DIR="$prefix/log" \
  PREFIX="$prefix" CALLER="$caller" PORT="$port" \
  bash -euo pipefail -c '
    set +u  # the setup files read unset variables
    _CATKIN_SETUP_DIR=$PREFIX source "$PREFIX/setup.bash"
    set -u
    found=$(rospack find rigid_body_sim)
    [ "$found" = "$PREFIX/share/rigid_body_sim" ] || {
      echo "[install_test] rospack finds $found, not the install space" >&2; exit 1; }
    echo "[install_test] roslaunch -p $PORT rigid_body_sim demo.launch"
    setsid roslaunch -p "$PORT" rigid_body_sim demo.launch > "$PREFIX/launch.log" 2>&1 &
    echo $! > "$PREFIX/launch.pid"
    models() {
      python3 - <<EOF
import rosgraph, rospy, time
from rigid_body_sim.srv import GetWorldProperties
deadline = time.monotonic() + 60
while not rosgraph.is_master_online() and time.monotonic() < deadline:
    time.sleep(0.2)
rospy.init_node("install_test", anonymous=True, disable_signals=True)
rospy.wait_for_service("/rigid_body_sim/get_world_properties", timeout=60)
print(" ".join(rospy.ServiceProxy("/rigid_body_sim/get_world_properties", GetWorldProperties)().model_names))
EOF
    }
    demo=$(models)
    count=$(wc -w <<< "$demo")
    [ "$count" = 19 ] || { echo "[install_test] demo has $count models: $demo" >&2;
                           cat "$PREFIX/launch.log" >&2; exit 1; }
    cd "$CALLER"
    rosrun rigid_body_sim spawn_model -urdf -file models/box.urdf -model installed_box -z 3
    models | grep -qw installed_box || { echo "[install_test] installed_box missing" >&2; exit 1; }
    echo "[install_test] the install space runs the demo (17 models) and spawn_model"
  ' &
runner=$!
# The launch is started inside the runner; its pid is read back for cleanup.
for _ in $(seq 100); do [ -s "$prefix/launch.pid" ] && break; sleep 0.1; done
launch_pid=$(cat "$prefix/launch.pid" 2> /dev/null || true)
wait "$runner"
