#!/usr/bin/env bash
# Installs the Debian packages the build, the tests and the demo need.
# Idempotent: runs apt-get only when a package is missing.
set -euo pipefail

packages=(
  build-essential cmake git
  catkin ros-core-dev libroscpp-dev libroslib-dev ros-message-generation ros-message-runtime
  libtf2-ros-dev liburdfdom-dev liburdf-dev libdiagnostic-updater-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libstd-msgs-dev libstd-srvs-dev libgeometry-msgs-dev libvisualization-msgs-dev libsensor-msgs-dev
  libassimp-dev libqhull-dev libeigen3-dev
  libgtest-dev googletest librostest-dev python3-rostest python3-rosunit rosbash
  libbullet-dev libbenchmark-dev python3-matplotlib
  libros-rosgraph-msgs-dev libtf2-msgs-dev python3-rospy rviz xvfb imagemagick
  python3-geometry-msgs python3-std-msgs python3-std-srvs python3-visualization-msgs
  python3-rosgraph-msgs python3-tf2-msgs python3-diagnostic-msgs python3-sensor-msgs
  python3-trajectory-msgs libtrajectory-msgs-dev libnav-msgs-dev python3-nav-msgs python3-tf2-ros
  clang libclang-rt-14-dev
  ros-robot-state-publisher tf2-tools python3-yaml
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "[deps] all ${#packages[@]} Debian packages are installed"
  exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
  echo "[deps] missing packages: ${missing[*]}" >&2
  echo "[deps] run as root, or install them with: sudo apt-get install ${missing[*]}" >&2
  exit 1
fi

echo "[deps] installing ${#missing[@]} packages: ${missing[*]}"
# Another apt (unattended-upgrades, a second make) may hold the dpkg lock:
# wait for it, up to DEPS_LOCK_TIMEOUT seconds, instead of failing at once.
lock_timeout=${DEPS_LOCK_TIMEOUT:-600}
if command -v fuser > /dev/null && fuser /var/lib/dpkg/lock-frontend /var/lib/apt/lists/lock > /dev/null 2>&1; then
  echo "[deps] another apt holds the dpkg lock; waiting up to ${lock_timeout} s for it"
fi
echo "[deps] apt-get update ..."
apt-get -o DPkg::Lock::Timeout="$lock_timeout" update -q
echo "[deps] apt-get install ..."
DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout="$lock_timeout" install -y -q \
  --no-install-recommends "${missing[@]}" \
  | grep --line-buffered -E '^(Setting up|Unpacking|E:)' || true
for package in "${missing[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    echo "[deps] failed to install $package" >&2
    exit 1
  fi
done
echo "[deps] done"
