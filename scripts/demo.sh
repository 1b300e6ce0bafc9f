#!/usr/bin/env bash
# The main job: sets up .venv if needed, then runs the MIndGrasp demo headless: simulated arm, virtual
# amplifier + virtual subject, classifier, vision, controller, recorded to runs/.
# Arguments go to `mindgrasp launch demo` (e.g. scripts/demo.sh duration:=120 gui:=true).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
exec .venv/bin/mindgrasp launch demo "$@"
