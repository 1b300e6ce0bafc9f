#!/usr/bin/env bash
# Build the ROS 2 Jazzy core (rclpy, rmw_cyclonedds_cpp, the ros2 CLI, launch, common messages)
# and mindgrasp_msgs into a cache outside the clone, for the `ros2_real` tests.
#
#   scripts/build_ros2.sh [SRC]     # SRC: a sources tarball (default ../shared/ros2/
#                                   # jazzy-core-src.tar.gz) or a folder with src/ (what
#                                   # `vcs import src < ros2.repos` gives on a networked machine)
#   scripts/build_ros2.sh --env     # print the path of the env.sh to source (build if needed)
#
# The cache, ${MINDGRASP_ROS2_CACHE:-~/.cache/mindgrasp/ros2-jazzy}/<hash of the sources>/, holds
# venv/ (colcon, empy 3), install/ and env.sh; a second run with the same sources only checks.
# mindgrasp_msgs is built on top into msgs-<hash of its files>/ (16 s). Where ROS 2 Jazzy is
# installed and sourced already (ROS_DISTRO=jazzy and ros2 on PATH), that one is used and nothing
# is built. Debian packages the build needs (as root: apt-get install ...): cmake g++ python3-dev
# python3-venv libyaml-dev libspdlog-dev pybind11-dev libssl-dev libacl1-dev libtinyxml2-dev
# python3-numpy python3-lark python3-yaml python3-psutil python3-netifaces python3-catkin-pkg
# python3-packaging python3-argcomplete. Build time: about 7 min on 2 idle cores, 21 min on
# 2 cores shared with other work (load 6-7); mindgrasp_msgs 30 s.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
print_env=false
if [ "${1:-}" = "--env" ]; then print_env=true; shift; fi
src=${1:-$repo/../shared/ros2/jazzy-core-src.tar.gz}
log() { if $print_env; then echo "build_ros2: $*" >&2; else echo "build_ros2: $*"; fi; }
fail() { echo "build_ros2: $*" >&2; exit 2; }

if [ "${ROS_DISTRO:-}" = jazzy ] && command -v ros2 >/dev/null 2>&1; then
  log "using the ROS 2 Jazzy already sourced ($(command -v ros2)); nothing to build."
  if $print_env; then echo ""; fi
  exit 0
fi

[ -e "$src" ] || fail "no ROS 2 sources at $src; give a tarball or a folder with src/ (vcs import)."
missing=()
for tool in cmake g++ /usr/bin/python3; do command -v "$tool" >/dev/null 2>&1 || missing+=("$tool"); done
for header in /usr/include/yaml.h /usr/include/spdlog/spdlog.h /usr/include/pybind11/pybind11.h \
              /usr/include/openssl/ssl.h /usr/include/acl/libacl.h /usr/include/tinyxml2.h; do
  [ -e "$header" ] || missing+=("$header")
done
/usr/bin/python3 -c 'import numpy, lark, yaml, catkin_pkg, netifaces, psutil' 2>/dev/null \
  || missing+=("python3-numpy python3-lark python3-yaml python3-catkin-pkg python3-netifaces python3-psutil")
[ ${#missing[@]} -eq 0 ] || fail "missing build dependencies: ${missing[*]}; install the Debian packages listed at the top of this script."

if [ -d "$src" ]; then
  [ -d "$src/src" ] || fail "$src has no src/ folder; give the folder \`vcs import src\` filled."
  key=$(cd "$src" && find src -type f -printf '%P %s %T@\n' | sort | sha256sum | cut -c1-16)
else
  key=$(sha256sum "$src" | cut -c1-16)
fi
cache=${MINDGRASP_ROS2_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/mindgrasp/ros2-jazzy}/$key
core_done=$cache/.core-built

packages=(rclpy rmw_cyclonedds_cpp ros2topic ros2service ros2param ros2node ros2interface ros2launch
          launch_ros ros_environment std_srvs sensor_msgs diagnostic_msgs visualization_msgs
          trajectory_msgs tf2_msgs)
colcon_args=(--merge-install --parallel-workers 2 --event-handlers console_direct- status-
             --cmake-args -DBUILD_TESTING=OFF -DCMAKE_BUILD_TYPE=Release -DTRACETOOLS_DISABLED=ON)

if [ ! -f "$core_done" ]; then
  start=$(date +%s)
  log "building the ROS 2 Jazzy core from $src into $cache (7-20 min on 2 cores) ..."
  rm -rf "$cache" && mkdir -p "$cache/ws"
  /usr/bin/python3 -m venv --system-site-packages "$cache/venv"
  "$cache/venv/bin/python" -m pip install --quiet colcon-common-extensions 'empy==3.3.4' \
    >"$cache/pip.log" 2>&1 || fail "pip could not install colcon and empy; see $cache/pip.log"
  if [ -d "$src" ]; then cp -a "$src/src" "$cache/ws/src"; else tar -xzf "$src" -C "$cache/ws"; fi
  # test-only packages: left out (colcon's --packages-skip fails on a fresh install directory)
  find "$cache/ws/src" -maxdepth 3 -type d \( -name test_interface_files -o -name test_msgs \) \
    -exec touch {}/COLCON_IGNORE \;
  (set +u && cd "$cache/ws" && . "$cache/venv/bin/activate" && export ROS_DISTRO_OVERRIDE=jazzy MAKEFLAGS=-j2 \
     && colcon build --base-paths src --install-base "$cache/install" --build-base "$cache/build" \
          --packages-up-to "${packages[@]}" "${colcon_args[@]}") >"$cache/build.log" 2>&1 \
    || fail "the core build failed; see $cache/build.log"
  rm -rf "$cache/build" "$cache/ws"
  echo "$(( $(date +%s) - start ))" >"$core_done"
  log "core built in $(cat "$core_done") s."
fi

# mindgrasp_msgs on top, keyed by its files (a change of a .msg rebuilds only this)
msgs_key=$(cd "$repo/src/mindgrasp_msgs" && find . -type f -printf '%P %s\n' -exec cat {} \; | sha256sum | cut -c1-16)
msgs=$cache/msgs-$msgs_key
if [ ! -f "$msgs/.built" ]; then
  log "building mindgrasp_msgs with rosidl into $msgs ..."
  rm -rf "$msgs" && mkdir -p "$msgs/src"
  cp -a "$repo/src/mindgrasp_msgs" "$msgs/src/"
  # setup.bash reads unset variables (COLCON_TRACE ...): sourced without set -u
  (set +u && cd "$msgs" && . "$cache/venv/bin/activate" && . "$cache/install/setup.bash" \
     && export MAKEFLAGS=-j2 && colcon build --base-paths src --install-base "$msgs/install" \
          --build-base "$msgs/build" "${colcon_args[@]}") >"$msgs/build.log" 2>&1 \
    || fail "the mindgrasp_msgs build failed; see $msgs/build.log"
  rm -rf "$msgs/build"
  touch "$msgs/.built"
fi

cat >"$cache/env.sh" <<EOF
# source this: the ROS 2 Jazzy core built by scripts/build_ros2.sh, with mindgrasp_msgs
. "$cache/venv/bin/activate"
. "$cache/install/setup.bash"
. "$msgs/install/setup.bash"
export RMW_IMPLEMENTATION=rmw_cyclonedds_cpp ROS_DISTRO=jazzy
EOF
if $print_env; then echo "$cache/env.sh"; else log "ready: . $cache/env.sh"; fi
