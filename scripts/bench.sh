#!/usr/bin/env bash
# The whole benchmark suite in one command: every latency and throughput tool, --rounds times
# (default 5), then the tables (median and min-max over rounds), summary.json / summary.md and
# the plots (PNG) in the output folder (default bench/results). About 15-20 minutes on 2 vCPUs.
#
#   scripts/bench.sh [--rounds N] [--quick] [--out DIR] [--only "local shm fanout hybrid network"] [--no-build]
#
# Parts: local (horus-latency-local: threads, with the true floor and boost), shm
# (horus-latency-shm: processes, with the true floor and iceoryx), fanout (horus-fanout: 1 -> N
# subscriber processes, many topics, memory), hybrid (bench/fleet/hybrid.sh: a fleet topic's
# local and remote subscribers against a host topic, with the host's bridge in the publisher, in
# the subscriber's process or in a third process, on each backend; root: namespace hosts),
# network (bench/dds and bench/lcm: horus against
# the raw Cyclone DDS, Fast DDS and LCM programs, on loopback and between two namespace hosts;
# the namespace part needs root). Every tool's own output goes to DIR/bench.log.
# --quick: one short round of each (a smoke run). Plots need python3-matplotlib and the network
# part's context-switch count (bench/net_wakeups.sh) perf (linux-perf), which this script
# installs with apt-get when they are missing and it runs as root.
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=5
quick=0
out=bench/results
only="local shm fanout hybrid network"
build=1
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) rounds="$2"; shift ;;
    --quick) quick=1 ;;
    --out) out="$2"; shift ;;
    --only) only="$2"; shift ;;
    --no-build) build=0 ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "bench.sh: unknown argument '$1' (expected --rounds N, --quick, --out DIR, --only LIST, --no-build)" >&2; exit 2 ;;
  esac
  shift
done
case "$rounds" in ''|*[!0-9]*) echo "bench.sh: --rounds takes a positive number, not '$rounds'" >&2; exit 2 ;; esac
[ "$rounds" -ge 1 ] || { echo "bench.sh: --rounds must be at least 1" >&2; exit 2; }
for part in $only; do
  case "$part" in local|shm|fanout|hybrid|network) ;; *) echo "bench.sh: unknown part '$part' (expected local, shm, fanout, hybrid, network)" >&2; exit 2 ;; esac
done
[ "$quick" = 1 ] && rounds=1
want() { [[ " $only " == *" $1 "* ]]; }

# Debian's Python sees Debian's python3-matplotlib (a python3 earlier in PATH may not).
py=python3
[ -x /usr/bin/python3 ] && py=/usr/bin/python3
# A Debian package, when this runs as root and it is missing: apt_install PACKAGE WHAT-FOR
apt_install() {
  [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null || return 1
  echo "bench.sh: installing $1 for $2"
  apt-get install -y -q "$1" >/dev/null 2>&1 ||
    (apt-get update -q >/dev/null 2>&1 && apt-get install -y -q "$1" >/dev/null 2>&1)
}
if ! "$py" -c 'import matplotlib' 2>/dev/null; then
  apt_install python3-matplotlib "the plots" ||
    echo "bench.sh: python3-matplotlib is not installed: the tables are printed, the plots skipped"
fi
if want network && ! command -v perf >/dev/null 2>&1; then
  apt_install linux-perf "the context-switch count of the network benchmark" || true
fi

bin=build/default/bench
if [ "$build" = 1 ]; then
  cmake --preset default >/dev/null
  targets=(horus_latency_local horus_latency_shm horus_fanout)
  want network && targets+=(horus_dds_pingpong horus_wake_latency horus_ros2_convert)
  want hybrid && targets+=(horus_fleet_hybrid)
  cmake --build --preset default -j "$(nproc)" --target "${targets[@]}"
  # The raw baselines exist when their generators were found at configure time.
  if want network; then
    for t in raw_cyclone_pingpong raw_fastdds_pingpong raw_lcm_pingpong; do
      cmake --build --preset default -j "$(nproc)" --target "$t" >/dev/null 2>&1 || echo "bench.sh: $t not built (its generator is missing): skipped"
    done
  fi
fi

mkdir -p "$out"
# Only the results of the parts that run now are replaced (the report reads whatever is there).
want local && rm -f "$out"/local.*.json
want shm && rm -f "$out"/shm.*.json
want fanout && rm -f "$out"/fanout.json
want hybrid && rm -f "$out"/hybrid.txt
want network && rm -f "$out"/network.txt "$out"/net_wakeups.txt "$out"/ros2_convert.txt
rm -f "$out"/*.png "$out"/summary.*
log="$out/bench.log"
: >"$log"
q=()
[ "$quick" = 1 ] && q=(--quick)
start=$SECONDS
step() { printf '[%4ds] %s\n' $((SECONDS - start)) "$*"; }

for r in $(seq 1 "$rounds"); do
  if want local; then
    step "round $r/$rounds: horus-latency-local"
    "$bin/horus-latency-local" "${q[@]}" --json "$out/local.$r.json" >>"$log" 2>&1
  fi
  if want shm; then
    step "round $r/$rounds: horus-latency-shm"
    "$bin/horus-latency-shm" "${q[@]}" --json "$out/shm.$r.json" >>"$log" 2>&1
  fi
done
if want fanout; then
  step "horus-fanout, $rounds rounds"
  "$bin/horus-fanout" "${q[@]}" --rounds "$rounds" --json "$out/fanout.json" >>"$log" 2>&1
fi
if want hybrid; then
  if [ "$(id -u)" = 0 ]; then
    step "hybrid: fleet topics' local and remote subscribers against a host topic, each bridge holder and backend, $rounds rounds"
    n_hy=1500
    [ "$quick" = 1 ] && n_hy=300
    bench/fleet/hybrid.sh --rounds "$rounds" --count "$n_hy" --results "$out/hybrid.txt" >>"$log" 2>&1 ||
      echo "bench.sh: the hybrid benchmark failed (see $log)"
  else
    echo "bench.sh: the hybrid part needs root (namespace hosts): skipped"
  fi
fi
if want network; then
  : >"$out/network.txt"
  step "DDS: horus against raw Cyclone DDS and Fast DDS, $rounds rounds"
  HORUS_BENCH_RESULTS="$out/network.txt" bench/dds/run_dds_bench.sh "${q[@]}" --rounds "$rounds" >>"$log" 2>&1 ||
    echo "bench.sh: the DDS benchmark failed (see $log)"
  step "ROS 2: the conversion per message of a topic mapped onto ROS 2, against horus's own encoding, $rounds rounds"
  "$bin/horus-ros2-convert" --rounds "$rounds" $([ "$quick" = 1 ] && echo --samples 500) >"$out/ros2_convert.txt" 2>>"$log" ||
    echo "bench.sh: horus-ros2-convert failed (see $log)"
  step "LCM: horus against raw LCM, $rounds rounds"
  HORUS_BENCH_RESULTS="$out/network.txt" bench/lcm/run_lcm_bench.sh "${q[@]}" --rounds "$rounds" >>"$log" 2>&1 ||
    echo "bench.sh: the LCM benchmark failed (see $log)"
  if command -v perf >/dev/null 2>&1; then
    step "where the network latency goes: context switches per round trip (bench/net_wakeups.sh)"
    n_rt=10000
    [ "$quick" = 1 ] && n_rt=1000
    bench/net_wakeups.sh --n "$n_rt" >"$out/net_wakeups.txt" 2>>"$log" ||
      { echo "bench.sh: net_wakeups.sh failed (see $log)"; rm -f "$out/net_wakeups.txt"; }
  else
    echo "bench.sh: perf is not installed: the context-switch count (bench/net_wakeups.sh) is skipped"
  fi
fi
step "report"
echo "horus benchmark suite: $rounds round(s), $(nproc) CPUs, $(uname -r), $(date -u +%Y-%m-%dT%H:%MZ)" | tee "$out/run.txt"
"$py" bench/report.py "$out"
step "done: tables in $out/summary.md, figures in $out/summary.json, plots in $out/*.png, tool output in $log"
