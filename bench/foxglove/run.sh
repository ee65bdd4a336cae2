#!/usr/bin/env bash
# What horus foxglove costs (bench_foxglove.py): builds the CLI and the publisher, then runs it.
# Arguments go to bench_foxglove.py (--rounds N, --seconds S, --cpu-seconds S, --clients N).
# Needs node and the npm packages of tests/interop/foxglove_js (scripts/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/../.."
cmake --preset default >/dev/null
cmake --build --preset default --target horus_cli horus_fox_bench_peer
exec python3 bench/foxglove/bench_foxglove.py --peer build/default/bench/horus-fox-bench-peer \
  --cli build/default/tools/horus "$@"
