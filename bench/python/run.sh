#!/usr/bin/env bash
# The Python benchmark (bench_python.py): builds the module and the C++ peer, then runs it with
# Debian's python3 (the one with python3-numpy). Arguments go to bench_python.py (--quick,
# --rounds N, --count N).
set -euo pipefail
cd "$(dirname "$0")/../.."
cmake --preset default >/dev/null
cmake --build --preset default --target horus_python horus_py_peer
py=python3
[ -x /usr/bin/python3 ] && py=/usr/bin/python3
exec env PYTHONPATH="$PWD/build/default/python" "$py" bench/python/bench_python.py --peer build/default/bench/horus-py-peer "$@"
