#!/usr/bin/env bash
# The test command: sets up .venv if needed, then runs the whole test suite.
# Extra arguments go to pytest (e.g. scripts/test.sh -m "not slow" -x).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
# Keep DDS traffic of the tests on this host and away from other ROS 2 graphs.
export ROS_AUTOMATIC_DISCOVERY_RANGE=${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}
export ROS_DOMAIN_ID=${ROS_DOMAIN_ID:-$(( (RANDOM % 100) + 100 ))}
export MNE_DATASETS_EEGBCI_PATH=${MNE_DATASETS_EEGBCI_PATH:-$(cd .. && pwd)/shared/data}
exec .venv/bin/python -m pytest "$@"
