#!/usr/bin/env bash
# Set up MIndGrasp-ROS on a fresh machine: a project-local virtual environment `.venv` with pinned
# versions (constraints.txt; torch==2.13.0 CPU), the project installed editable. Idempotent: a second
# run only checks. Debian packages: none are needed to run MIndGrasp (PyBullet renders headless with
# TinyRenderer, pylsl bundles liblsl, cyclonedds bundles Cyclone DDS); see README for the optional
# GUI. For the tests, when this runs as root: Xvfb (the display window tests). The test command
# also builds a real ROS 2 Jazzy core once per machine (scripts/test.sh, scripts/build_ros2.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
stamp=.venv/.mindgrasp-installed
# the packages' setup.py files too: their mindgrasp.* entry points (the mindgrasp command's
# commands and verbs) are installed by the root setup.py, so a changed one re-installs
want=$(cat pyproject.toml constraints.txt setup.py src/mindgrasp_*/setup.py | sha256sum | cut -d' ' -f1)
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
echo "$want" > "$stamp"
echo "setup: .venv ready ($(.venv/bin/python --version))"
