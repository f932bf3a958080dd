#!/usr/bin/env bash
# One-stop set-up for a fresh Debian bookworm machine:
#   ./bootstrap.sh run [sketchnav run options]   install deps, build, run the main job
#   ./bootstrap.sh test                          install deps, build, run the whole test suite
#   ./bootstrap.sh build                         install deps and build only
# Installs only the Debian packages that are missing (apt-get, non-interactive), configures
# the Release preset once and rebuilds incrementally, so a second run is fast.
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)
MODE=${1:-run}
shift || true

# Debian packages the build, the tests and the main job need.
PACKAGES=(
  build-essential cmake pkg-config ccache git
  libopencv-dev libopencv-contrib-dev libeigen3-dev libvisp-dev libmrpt-dev
  libaravis-dev aravis-tools libusb-1.0-0-dev
  nlohmann-json3-dev libcpp-httplib-dev libssl-dev zlib1g-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  visp-images-data mrpt-common
  chromium
  # ROS 1 (Debian's Noetic-era core) for sketchnav::ros and `sketchnav ros` (doc/ros.md); the
  # message headers, tf2 and cv_bridge to build it, rosmaster for its tests.
  libroscpp-dev libcv-bridge-dev libtf2-ros-dev libstd-msgs-dev libsensor-msgs-dev
  libnav-msgs-dev libgeometry-msgs-dev libros-rosgraph-msgs-dev librosbag-storage-dev python3-rosmaster
  # the route action (generated at build time: genaction + gencpp, the .msg definitions)
  libactionlib-dev libactionlib-msgs-dev python3-genmsg python3-gencpp ros-std-msgs
  ros-actionlib-msgs
  # the action's Python messages (genpy) and the rospy + actionlib client ros/scripts/sketchnav_route.py
  python3-genpy python3-rospy python3-actionlib
  # /diagnostics, the annotated image, rviz markers; roslaunch / rostopic / rosbag record for
  # the tests
  libdiagnostic-updater-dev libdiagnostic-msgs-dev libimage-transport-dev
  libvisualization-msgs-dev libtf2-msgs-dev python3-roslaunch python3-rostopic python3-rosbag
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
# Node may come from Debian (nodejs + npm) or from a vendor package that bundles npm.
command -v node >/dev/null 2>&1 || missing+=(nodejs)
command -v npm >/dev/null 2>&1 || missing+=(npm)
if ((${#missing[@]})); then
  echo "bootstrap: installing ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Browser tests drive Debian's chromium with playwright-core from npm (no browser download).
if [ "$MODE" = "test" ] && [ -f tests/browser/package.json ] && [ ! -d tests/browser/node_modules ]; then
  (cd tests/browser && npm ci --no-audit --no-fund --loglevel=error)
fi

JOBS=${SKETCHNAV_JOBS:-$(nproc)}
if [ ! -f build/release/CMakeCache.txt ]; then
  cmake --preset release >/dev/null
fi
cmake --build build/release -j "$JOBS"

case "$MODE" in
  build) ;;
  run)
    exec build/release/apps/sketchnav run "$@"
    ;;
  test)
    cd build/release
    exec ctest --output-on-failure -j "$JOBS" --timeout 900 "$@"
    ;;
  *)
    echo "usage: ./bootstrap.sh run|test|build [args]" >&2
    exit 2
    ;;
esac
