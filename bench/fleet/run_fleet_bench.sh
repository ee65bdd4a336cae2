#!/usr/bin/env bash
# The fleet layer's figures on each backend, between two namespace hosts (needs root; nothing
# leaves this machine): discovery time (both processes started -> each host seen), loss detection
# time (link down -> host lost) with the default 100 ms heartbeat, and the network cost at rest
# (bytes/s a host sends with the fleet layer announcing, and with `fleet.announce: false`: what
# the transport itself sends for the same topics). Uses tests/horus_fleet_watch of the build.
#
#   sudo bench/fleet/run_fleet_bench.sh [--rounds 5] [--backend all|cyclonedds|fastdds|lcm] [--build build/default]
set -euo pipefail
cd "$(dirname "$0")/../.."
rounds=5
backends="cyclonedds fastdds lcm"
build=build/default
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) rounds="$2"; shift 2 ;;
    --backend) [ "$2" = all ] || backends="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    *) echo "run_fleet_bench.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ "$(id -u)" = 0 ] || { echo "run_fleet_bench.sh: needs root (namespace hosts)" >&2; exit 1; }
watch="$PWD/$build/tests/horus_fleet_watch"
[ -x "$watch" ] || { echo "run_fleet_bench.sh: $watch is missing; build the tests first" >&2; exit 1; }
. scripts/lib/netns-hosts.sh
work="$(mktemp -d /tmp/horus-fleet-bench.XXXXXX)"
trap 'nh_cleanup; rm -rf "$work"' EXIT
ms() { date +%s%3N; }
env_for() {  # the backend, a DDS domain and an LCM port of this run
  echo "HORUS_BACKEND=$1 HORUS_DOMAIN_ID=$(( $$ % 200 + 1 )) HORUS_DDS_LOCALHOST=0 HORUS_LCM_URL=udpm://239.255.76.69:$(( 20000 + $$ % 20000 ))?ttl=1"
}
field() {  # field FILE PATTERN: the time (last word) of the first line matching PATTERN
  grep -m1 -E "$2" "$1" | awk '{print $NF}'
}
tx_bytes() { ip netns exec "${nh_prefix}h$1" cat /sys/class/net/eth0/statistics/tx_bytes; }

# One round: discovery and loss detection, from host 1's view of host 2.
round() {
  local backend="$1" r="$2"
  nh_create "hfb$$r$r" "10.215.$(( ($$ + r) % 250 + 1 ))" fbh1 fbh2
  # shellcheck disable=SC2046
  nh_on 1 env $(env_for "$backend") "$watch" 6 >"$work/w1" 2>&1 &
  local a=$!
  # shellcheck disable=SC2046
  nh_on 2 env $(env_for "$backend") "$watch" 6 >"$work/w2" 2>&1 &
  local b=$!
  sleep 3
  local down
  down=$(ms)
  nh_link 2 down
  # Up again before the processes end: Cyclone DDS cannot delete a participant whose link is down
  # (its receive threads wait for a packet it sends itself).
  sleep 1.5
  nh_link 2 up
  wait "$a" "$b" || true
  local s1 s2 joined lost
  s1=$(field "$work/w1" '^start')
  s2=$(field "$work/w2" '^start')
  joined=$(field "$work/w1" '^event joined fbh2 ')
  lost=$(field "$work/w1" '^event lost fbh2 ')
  nh_cleanup
  local start=$(( s1 > s2 ? s1 : s2 ))
  echo "$backend discovery $(( ${joined:-0} - start )) loss $(( ${lost:-0} - down ))"
}

# Bytes/s host 1 sends at rest over 10 s, with the fleet layer announcing or not.
rest() {
  local backend="$1" announce="$2"
  printf 'fleet:\n  announce: %s\n' "$announce" >"$work/config.yaml"
  nh_create "hfr$$" "10.216.$(( $$ % 250 + 1 ))" frh1 frh2
  # shellcheck disable=SC2046
  nh_on 1 env $(env_for "$backend") HORUS_CONFIG="$work/config.yaml" "$watch" 16 >/dev/null 2>&1 &
  local a=$!
  # shellcheck disable=SC2046
  nh_on 2 env $(env_for "$backend") HORUS_CONFIG="$work/config.yaml" "$watch" 16 >/dev/null 2>&1 &
  local b=$!
  sleep 4
  local b0 b1
  b0=$(tx_bytes 1)
  sleep 10
  b1=$(tx_bytes 1)
  wait "$a" "$b" || true
  nh_cleanup
  echo "$backend rest_$announce $(( (b1 - b0) / 10 ))"
}

for backend in $backends; do
  for r in $(seq "$rounds"); do round "$backend" "$r"; done
  rest "$backend" true
  rest "$backend" false
done | tee "$work/raw.txt"
python3 - "$work/raw.txt" <<'PY'
import statistics, sys
rows = {}
for line in open(sys.argv[1]):
    w = line.split()
    b = rows.setdefault(w[0], {"discovery": [], "loss": [], "rest_true": None, "rest_false": None})
    if w[1] == "discovery":
        b["discovery"].append(int(w[2])); b["loss"].append(int(w[4]))
    else:
        b[w[1]] = int(w[2])
def s(v):
    return f"{statistics.median(v):.0f} ({min(v)}-{max(v)})" if v else "-"
print()
print("| backend | discovery ms, median (range) | loss detection ms, median (range) | at rest, fleet layer on | off (the transport alone) | the fleet layer's cost |")
print("|---|---|---|---|---|---|")
for k, b in rows.items():
    on, off = b["rest_true"], b["rest_false"]
    print(f"| {k} | {s(b['discovery'])} | {s(b['loss'])} | {on} B/s | {off} B/s | {on - off} B/s |")
PY
