#!/usr/bin/env bash
# The test command: sets up .venv if needed, then runs the whole test suite.
# Extra arguments go to pytest (e.g. scripts/test.sh -m "not slow" -x; -n 0 runs in one process).
# Two pytest-xdist workers by default (MINDGRASP_TEST_WORKERS): most tests wait on other
# processes, so two at a time use the 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
# Keep DDS traffic of the tests on this host; each test process claims a ROS domain of its own
# that no other test process on this host holds (tests/conftest.py).
export ROS_AUTOMATIC_DISCOVERY_RANGE=${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}
export MNE_DATASETS_EEGBCI_PATH=${MNE_DATASETS_EEGBCI_PATH:-$(cd .. && pwd)/shared/data}
exec .venv/bin/python -m pytest -n "${MINDGRASP_TEST_WORKERS:-2}" --dist loadfile "$@"
