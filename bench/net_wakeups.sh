#!/usr/bin/env bash
# Where horus's network latency goes: the context switches of one CmdVel round trip, horus
# against the raw library, on one host (loopback), beside the one-way latency of each and the
# cost of one cross-process wake-up on this machine (horus-wake-latency's raw futex ping-pong).
#
#   bench/net_wakeups.sh [--n ROUND_TRIPS] [--build-dir DIR]
#
# For each of raw-cyclone, horus-cyclonedds, raw-fastdds, horus-fastdds, raw-lcm, horus-lcm it
# runs the ping-pong of bench/dds and bench/lcm (same programs, same settings) once under
# `perf stat -a -e context-switches` (needs perf and root or perf_event_paranoid <= 0) and
# prints switches per round trip and the p50. A thread that sleeps and is woken costs two
# switches (off the CPU and back on); horus's extra switches per one-way, halved, times the
# wake-up cost, is the latency the extra hops explain.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="$here/../build/default"
n=20000
pin=""
while [ $# -gt 0 ]; do
  case "$1" in
    --n) n="$2"; shift ;;
    --build-dir) build="$2"; shift ;;
    --one-cpu) pin="taskset -c 0" ;;
    *) echo "usage: $0 [--n ROUND_TRIPS] [--build-dir DIR] [--one-cpu]" >&2; exit 2 ;;
  esac
  shift
done
bin="$build/bench"
. "$(dirname "$0")/build_on_demand.sh"
bench_build "$build" horus_dds_pingpong raw_cyclone_pingpong raw_fastdds_pingpong raw_lcm_pingpong horus_wake_latency
command -v perf >/dev/null || { echo "perf is not installed (apt-get install linux-perf)" >&2; exit 1; }
for p in horus-dds-pingpong raw-cyclone-pingpong raw-fastdds-pingpong raw-lcm-pingpong horus-wake-latency; do
  [ -x "$bin/$p" ] || { echo "$bin/$p is not built (cmake --build --preset default)" >&2; exit 1; }
done
domain=$(( 1 + $$ % 200 ))
port=$(( 20000 + $$ % 30000 ))
url="udpm://239.255.76.$(( 100 + $$ % 100 )):$port?ttl=0&recv_buf_size=8388608"
tmp="$(mktemp -d "${TMPDIR:-/tmp}/net_wakeups.XXXXXX")"
trap 'pkill -f "pingpong pong $domain cmdvel" 2>/dev/null; rm -rf "$tmp"' EXIT

prog() {
  case "$1" in
    raw-cyclone) echo "env BENCH_LOCALHOST=1 $bin/raw-cyclone-pingpong" ;;
    raw-fastdds) echo "env BENCH_LOCALHOST=1 $bin/raw-fastdds-pingpong" ;;
    horus-cyclonedds) echo "env BENCH_LOCALHOST=1 HORUS_BACKEND=cyclonedds $bin/horus-dds-pingpong" ;;
    horus-fastdds) echo "env BENCH_LOCALHOST=1 HORUS_BACKEND=fastdds $bin/horus-dds-pingpong" ;;
    raw-lcm) echo "env HORUS_LCM_URL=$url $bin/raw-lcm-pingpong" ;;
    horus-lcm) echo "env HORUS_LCM_URL=$url HORUS_BACKEND=lcm $bin/horus-dds-pingpong" ;;
  esac
}

# Rescheduling and function-call interrupts of every CPU so far.
ipis() { awk '$1 == "RES:" || $1 == "CAL:" { for (i = 2; i <= NF && $i ~ /^[0-9]+$/; ++i) s += $i } END { print s + 0 }' /proc/interrupts; }
echo "context switches per CmdVel round trip, one host, $n round trips each ($(nproc) CPUs${pin:+, every process on CPU 0})"
printf '%-18s %12s %10s %12s %10s\n' implementation switches/rt ipis/rt p50_us 'p99_us'
for impl in raw-cyclone horus-cyclonedds raw-fastdds horus-fastdds raw-lcm horus-lcm; do
  p="$(prog "$impl")"
  ( sleep 200 | $pin env HORUS_NAMESPACE=wk_b$$ $p pong $domain cmdvel 180 >"$tmp/pong.out" 2>&1 & )
  for _ in $(seq 1 50); do grep -q ready "$tmp/pong.out" 2>/dev/null && break; sleep 0.1; done
  i0="$(ipis)"
  perf stat -a -x, -e context-switches -o "$tmp/stat" -- \
    $pin env HORUS_NAMESPACE=wk_a$$ timeout 120 $p ping $domain cmdvel "$n" 500 >"$tmp/ping.out" 2>&1 || true
  i1="$(ipis)"
  pkill -f "pingpong pong $domain cmdvel" 2>/dev/null || true
  sleep 0.3
  res="$(grep RESULT "$tmp/ping.out" || true)"
  sw="$(grep context-switches "$tmp/stat" 2>/dev/null | cut -d, -f1 || true)"
  if [ -z "$res" ] || [ -z "$sw" ]; then echo "$impl: FAILED $(head -c 200 "$tmp/ping.out")"; continue; fi
  p50="$(sed -n 's/.*p50_ns=\([0-9.]*\).*/\1/p' <<<"$res")"
  p99="$(sed -n 's/.*p99_ns=\([0-9.]*\).*/\1/p' <<<"$res")"
  # warm-up round trips count too: n + 500
  awk -v s="$sw" -v q=$((i1 - i0)) -v n="$n" -v i="$impl" -v a="$p50" -v b="$p99" \
    'BEGIN { printf "%-18s %12.1f %10.2f %12.1f %10.1f\n", i, s / (n + 500), q / (n + 500), a / 1000, b / 1000 }'
done
echo
echo "one cross-process wake-up on this machine (horus-wake-latency, raw futex ping-pong, one-way):"
"$bin/horus-wake-latency" --rounds 3 2>&1 | grep -iE "futex ping-pong|all rounds" || true
