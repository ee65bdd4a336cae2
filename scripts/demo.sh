#!/usr/bin/env bash
# Sets up everything, builds, and runs the fleet demo. Extra arguments go to the demo
# (e.g. scripts/demo.sh --robots 5 --duration 10).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset default >/dev/null
cmake --build --preset default --target fleet_demo
exec build/default/examples/fleet_demo "$@"
