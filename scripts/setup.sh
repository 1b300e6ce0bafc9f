#!/usr/bin/env bash
# Set up MIndGrasp-ROS on a fresh machine: a project-local virtual environment `.venv` with pinned
# versions (constraints.txt; torch==2.13.0 CPU), the project installed editable. Idempotent: a second
# run only checks. Debian packages: none are needed to run MIndGrasp (PyBullet renders headless with
# TinyRenderer, pylsl bundles liblsl, cyclonedds bundles Cyclone DDS); see README for the optional
# GUI. For the tests, when this runs as root: Xvfb (the display window tests), and the compilers
# and headers that build a real ROS 2 Jazzy core (the ros2_real tests; scripts/build_ros2.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
stamp=.venv/.mindgrasp-installed
want=$(cat pyproject.toml constraints.txt | sha256sum | cut -d' ' -f1)
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
  exit 0
fi
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
.venv/bin/python -m pip install --quiet --upgrade pip
# torch first and pinned: an unpinned torch pulls GBs of CUDA packages.
.venv/bin/python -m pip install --quiet -c constraints.txt "torch==2.13.0"
# test + cluster: the suite runs the Ray test too
.venv/bin/python -m pip install --quiet -c constraints.txt -e ".[test,cluster]"
# Xvfb: the participant display's window tests run under a private X server. Installed when
# missing and apt-get can (root); otherwise those tests are skipped with the reason.
if ! command -v Xvfb >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    # The lock timeout makes a second setup running at the same time wait for the first's apt-get.
    { apt-get -o DPkg::Lock::Timeout=600 update -qq \
        && DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 install -y -qq xvfb; } >/dev/null \
      || echo "setup: could not install xvfb (window tests skip)"
  else
    echo "setup: Xvfb is missing; 'sudo apt-get install xvfb' runs the display window tests"
  fi
fi
# A real ROS 2 Jazzy core for the ros2_real tests (our nodes against real rclpy and the ros2 CLI):
# built once per machine from ../shared/ros2 into a cache outside the clone (7 min on 2 idle
# cores; a second setup only checks it). MINDGRASP_ROS2=0 skips it; where it cannot be built the
# ros2_real tests skip with the reason.
ros2_src=../shared/ros2/jazzy-core-src.tar.gz
if [ "${MINDGRASP_ROS2:-1}" != 0 ] && [ -e "$ros2_src" ] && ! { [ "${ROS_DISTRO:-}" = jazzy ] \
    && command -v ros2 >/dev/null 2>&1; }; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 \
      && { ! command -v cmake >/dev/null 2>&1 || ! [ -e /usr/include/spdlog/spdlog.h ] \
           || ! [ -e /usr/include/tinyxml2.h ] || ! [ -e /usr/include/acl/libacl.h ]; }; then
    { apt-get -o DPkg::Lock::Timeout=600 update -qq \
        && DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 install -y -qq \
          cmake g++ python3-dev python3-venv libyaml-dev libspdlog-dev pybind11-dev libssl-dev \
          libacl1-dev libtinyxml2-dev python3-numpy python3-lark python3-yaml python3-psutil \
          python3-netifaces python3-catkin-pkg python3-packaging python3-argcomplete; } \
      >/dev/null 2>&1 || echo "setup: could not install the ROS 2 build dependencies"
  fi
  echo "setup: building the ROS 2 Jazzy core for the ros2_real tests (once per machine)"
  ./scripts/build_ros2.sh "$ros2_src" >/tmp/mindgrasp-build-ros2-$$.log 2>&1 \
    || echo "setup: the ROS 2 build failed (log: /tmp/mindgrasp-build-ros2-$$.log); the ros2_real tests skip"
fi
echo "$want" > "$stamp"
echo "setup: .venv ready ($(.venv/bin/python --version))"
