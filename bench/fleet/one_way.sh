#!/usr/bin/env bash
# One-way latency by clock between two namespace hosts whose clocks differ: `horus bench ping`
# against a pong on a host whose clock is 2.5 s ahead (the fleet's test hook,
# HORUS_TEST_CLOCK_OFFSET_MS), on a clean link and on a link whose one direction is slow (tc tbf
# on the ping host's egress). Half the round trip splits the slow direction's delay evenly over
# both ways; each way by clock, corrected by the offset the fleet's heartbeats measured, shows
# where it is. Needs root; nothing leaves this machine.
#
#   sudo bench/fleet/one_way.sh [--rounds 2] [--backend all|cyclonedds|fastdds|lcm] [--rate 4mbit] [--size 4000]
#
# Prints, per backend, link and round: half the round trip p50/p99, each way by clock p50/p99
# (ping -> pong, pong -> ping), the offset found and its uncertainty, samples below 0 (ms).
set -euo pipefail
cd "$(dirname "$0")/../.."
rounds=2 backends="cyclonedds fastdds lcm" rate=4mbit size=4000 build=build/default
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) rounds="$2"; shift 2 ;;
    --backend) [ "$2" = all ] || backends="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --size) size="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    *) echo "one_way.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ "$(id -u)" = 0 ] || { echo "one_way.sh: needs root (namespace hosts)" >&2; exit 1; }
cli="$PWD/$build/tools/horus"
[ -x "$cli" ] || { echo "one_way.sh: $cli is missing; build first" >&2; exit 1; }
. scripts/lib/netns-hosts.sh
json="/tmp/horus-one-way.$$.json"
trap 'nh_cleanup; rm -f "$json"' EXIT
nh_create "ow$$" "10.215.$(( $$ % 250 + 1 ))" robot-a robot-b
printf "%-11s %-12s %9s %9s %9s %9s %9s %9s %12s %9s %6s  (CompressedImage of %s bytes at 50 Hz, 5 s)\n" backend link \
  half_p50 half_p99 there_p50 there_p99 back_p50 back_p99 offset_ms unc_ms below "$size"
field() { python3 -c "import json,sys; j=json.load(open('$json')); print($1)"; }
for round in $(seq "$rounds"); do
  for b in $backends; do
    env="HORUS_CONFIG= HORUS_BACKEND=$b HORUS_DOMAIN_ID=$(( $$ % 200 + 1 )) HORUS_DDS_LOCALHOST=0 HORUS_LCM_URL=udpm://239.255.76.71:$(( 20000 + $$ % 20000 ))?ttl=1"
    for link in clean "$rate"; do
      nh_on 2 env $env HORUS_TEST_CLOCK_OFFSET_MS=2500 timeout 60 "$cli" bench pong --once --topic-prefix "ow$round" > /dev/null 2>&1 &
      pong=$!
      if [ "$link" = clean ]; then tc -n "${nh_prefix}h1" qdisc del dev eth0 root 2>/dev/null || true
      else tc -n "${nh_prefix}h1" qdisc replace dev eth0 root tbf rate "$rate" burst 2kb latency 500ms; fi
      rm -f "$json"
      nh_on 1 env $env timeout 60 "$cli" bench ping --remote --topic-prefix "ow$round" --size "$size" --rate 50 \
        --duration 5 --warmup 3 -q --json "$json" > /dev/null 2>&1 || true
      if [ -s "$json" ]; then
        printf "%-11s %-12s %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f %12.3f %9.3f %6s\n" "$b" "$link" \
          "$(field "j['one_way_ns']['p50']/1e6")" "$(field "j['one_way_ns']['p99']/1e6")" \
          "$(field "j['by_clock']['forward_ns']['p50']/1e6")" "$(field "j['by_clock']['forward_ns']['p99']/1e6")" \
          "$(field "j['by_clock']['return_ns']['p50']/1e6")" "$(field "j['by_clock']['return_ns']['p99']/1e6")" \
          "$(field "j['clock']['offset_ns']/1e6")" "$(field "j['clock']['uncertainty_ns']/1e6")" \
          "$(field "j['by_clock']['below_zero']")"
      else
        printf "%-11s %-12s %s\n" "$b" "$link" "no result"
      fi
      wait "$pong" 2>/dev/null || true
    done
    tc -n "${nh_prefix}h1" qdisc del dev eth0 root 2>/dev/null || true
  done
done
