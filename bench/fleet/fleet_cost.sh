#!/usr/bin/env bash
# What fleet topics cost an idle process, per backend and number of topics (bench/horus_fleet_cost.cpp):
# threads horus adds, idle CPU (ms per s) and context switches per second, time to open them; a
# row of host topics as the reference. Runs in a network namespace of its own when root (loopback
# with a multicast route: nothing leaves this machine), else on loopback-only settings.
#
#   bench/fleet/fleet_cost.sh [--topics 1,100,1000] [--backends cyclonedds,fastdds,lcm] [--idle 5]
#                             [--rounds 3] [--build build/default]
# Writes bench/results/fleet_cost.json and .md.
set -euo pipefail
cd "$(dirname "$0")/../.."
build=build/default
args=()
rounds=3
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    --topics|--backends|--idle) args+=("$1" "$2"); shift 2 ;;
    *) echo "fleet_cost.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
. bench/build_on_demand.sh
bench_build "$build" horus_fleet_cost
bin="$PWD/$build/bench/horus-fleet-cost"
[ -x "$bin" ] || { echo "fleet_cost.sh: $bin is missing; build the benchmarks first" >&2; exit 1; }
mkdir -p bench/results
out=bench/results/fleet_cost.md
{
  echo "# Fleet topics at rest: threads, idle CPU, context switches ($(date -u +%F), $(nproc) CPUs)"
  echo
  echo "\`bench/fleet/fleet_cost.sh ${args[*]:-}\` ($rounds rounds; each row a fresh process)."
  echo
} > "$out"
json_all=()
for r in $(seq 1 "$rounds"); do
  echo "## round $r" | tee -a "$out"
  echo '```' >> "$out"
  json="$(mktemp /tmp/horus-fleet-cost.XXXXXX.json)"
  if [ "$(id -u)" = 0 ] && command -v unshare >/dev/null; then
    unshare -n sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' sh \
      "$bin" "${args[@]}" --json "$json" | tee -a "$out"
  else
    "$bin" "${args[@]}" --json "$json" | tee -a "$out"
  fi
  echo '```' >> "$out"
  json_all+=("$(cat "$json")")
  rm -f "$json"
done
printf '%s\n' "${json_all[@]}" > bench/results/fleet_cost.json
echo "fleet_cost.sh: wrote $out and bench/results/fleet_cost.json"
