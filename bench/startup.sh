#!/usr/bin/env bash
# Start-up cost (issue 51): how long a program takes from exec to exit, run N times each,
# interleaved, beside a baseline from the same run (/bin/true: fork + exec alone). Measures
#   horus --version                       the CLI: loading it (and libhorus.so) and parsing
#   examples/hello_topic                  the first Topic opened, a message sent and received
# for each build directory given (e.g. a shared build and a static one, or main's build):
#   bench/startup.sh [--runs N] BUILD_DIR [BUILD_DIR ...]      (default: build/default, 200 runs)
# Prints p50 / p90 / p99 in ms per program and build, and the median less the baseline's.
set -euo pipefail
runs=200
dirs=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --runs) runs=$2; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) dirs+=("$1"); shift ;;
  esac
done
[[ ${#dirs[@]} -gt 0 ]] || dirs=("$(cd "$(dirname "$0")/.." && pwd)/build/default")
progs=("/bin/true|baseline")
for d in "${dirs[@]}"; do
  [[ -x $d/tools/horus && -x $d/examples/hello_topic ]] || { echo "startup.sh: $d has no tools/horus or examples/hello_topic" >&2; exit 1; }
  progs+=("$d/tools/horus --version|$d: horus --version" "$d/examples/hello_topic|$d: hello_topic")
done
HORUS_BACKEND= python3 - "$runs" "${progs[@]}" <<'PY'
import subprocess, sys, time, statistics
runs = int(sys.argv[1])
progs = [p.split("|", 1) for p in sys.argv[2:]]
times = {label: [] for _, label in progs}
for _ in range(runs):
    for cmd, label in progs:  # interleaved: the machine's drift is shared
        t = time.perf_counter_ns()
        subprocess.run(cmd.split(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        times[label].append((time.perf_counter_ns() - t) / 1e6)
def q(v, p):
    v = sorted(v)
    return v[min(len(v) - 1, int(p * len(v)))]
base = statistics.median(times["baseline"])
print(f"{'program':70s} {'p50 ms':>8s} {'p90 ms':>8s} {'p99 ms':>8s} {'p50-base':>9s}")
for _, label in progs:
    v = times[label]
    print(f"{label:70s} {q(v,.5):8.2f} {q(v,.9):8.2f} {q(v,.99):8.2f} {statistics.median(v)-base:9.2f}")
print(f"({runs} runs each, interleaved)")
PY
