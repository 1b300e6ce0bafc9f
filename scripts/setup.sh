#!/usr/bin/env bash
# Set up MIndGrasp-ROS on a fresh machine: a project-local virtual environment `.venv` with pinned
# versions (constraints.txt; torch==2.13.0 CPU), the project installed editable. Idempotent: a second
# run only checks. Debian packages: none are needed (PyBullet renders headless with TinyRenderer,
# pylsl bundles liblsl, cyclonedds bundles Cyclone DDS); see README for the optional GUI.
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
.venv/bin/python -m pip install --quiet -c constraints.txt -e ".[test]"
echo "$want" > "$stamp"
echo "setup: .venv ready ($(.venv/bin/python --version))"
