#!/usr/bin/env bash
# A 1 MiB image topic (a 10 Hz camera: 84 Mbit/s) over a link that carries 20 Mbit/s (tc tbf
# on the camera host's egress) between two namespace hosts, on each backend: does the receiver
# get the newest frames with a bounded age, or an ever-growing backlog? The same run measures
# the same topic on the link without a limit (the baseline). Needs root; nothing leaves this
# machine.
#
#   sudo bench/fleet/slow_link.sh [--seconds 10] [--rate 20mbit] [--hz 10] [--rounds 2] [--backend all|cyclonedds|fastdds|lcm]
#                                 [--budget "1.5 MB/s"] [--link "2 MB/s"] [--queue 100ms] [--side 1024]
#
# --queue is the tbf queue's length in time (its `latency`): what the link buffers.
# --budget gives the camera topic that egress budget (max_bandwidth in a configuration file):
# the camera host then sends the newest frames the budget allows, instead of every frame.
# --link gives the camera host a link budget (network.max_bandwidth): the same, and Fast DDS
# paces each frame's fragments at it (a flow controller).
#
# Prints, per backend and round: frames received, their age p50 / p99 / max in ms, dropped_count.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=10 rate=20mbit hz=10 rounds=2 backends="cyclonedds fastdds lcm" build=build/default budget="" link="" queue=100ms side=1024
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --hz) hz="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    --backend) [ "$2" = all ] || backends="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --budget) budget="$2"; shift 2 ;;
    --queue) queue="$2"; shift 2 ;;
    --link) link="$2"; shift 2 ;;
    --side) side="$2"; shift 2 ;;
    *) echo "slow_link.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ "$(id -u)" = 0 ] || { echo "slow_link.sh: needs root (namespace hosts)" >&2; exit 1; }
. bench/build_on_demand.sh
bench_build "$build" horus_slow_link_image
prog="$PWD/$build/bench/horus-slow-link-image"
[ -x "$prog" ] || { echo "slow_link.sh: $prog is missing; build the benchmarks first" >&2; exit 1; }
. scripts/lib/netns-hosts.sh
trap 'nh_cleanup' EXIT
nh_create "sl$$" "10.214.$(( $$ % 250 + 1 ))" camera viewer
config=""
if [ -n "$budget" ] || [ -n "$link" ]; then
  config="$(mktemp /tmp/horus-slow-link.XXXXXX.yaml)"
  [ -z "$link" ] || printf 'network:\n  max_bandwidth: "%s"\n' "$link" > "$config"
  [ -z "$budget" ] || printf 'topics:\n  - match: "fleet.camera.**"\n    max_bandwidth: "%s"\n' "$budget" >> "$config"
  trap 'nh_cleanup; rm -f "$config"' EXIT
fi
printf "%-11s %-10s %5s %7s %7s %7s %8s  (%s, 1 MiB frames at %s Hz, %s s%s)\n" backend link frames p50_ms p99_ms max_ms dropped \
  "$rate, queue $queue" "$hz" "$seconds" "${budget:+, budget $budget}${link:+, link budget $link}"
for round in $(seq "$rounds"); do
  for b in $backends; do
    for link in unlimited "$rate"; do
      if [ "$link" != unlimited ]; then
        ip -n "${nh_prefix}h1" link set eth0 txqueuelen 1000
        tc -n "${nh_prefix}h1" qdisc replace dev eth0 root tbf rate "$rate" burst 64kb latency "$queue"
      else
        tc -n "${nh_prefix}h1" qdisc del dev eth0 root 2>/dev/null || true
      fi
      env="${config:+HORUS_CONFIG=$config }HORUS_BACKEND=$b HORUS_DOMAIN_ID=$(( $$ % 200 + 1 )) HORUS_DDS_LOCALHOST=0 HORUS_LCM_URL=udpm://239.255.76.70:$(( 20000 + $$ % 20000 ))?ttl=1&recv_buf_size=8388608"
      topic="camera.frames_${round}_$b"
      out="$(mktemp)"
      nh_on 2 env $env HORUS_BACKEND="$b" "$prog" sub "fleet.$topic" $(( seconds + 4 )) > "$out" 2>/dev/null &
      sub=$!
      sleep 2
      nh_on 1 env $env "$prog" pub "fleet.$topic" "$hz" "$seconds" "$side" > /dev/null 2>&1 || true
      wait "$sub" || true
      read -r _ frames _ _ p50 _ p99 _ max _ dropped < "$out" || true
      printf "%-11s %-10s %5s %7s %7s %7s %8s\n" "$b" "$link" "${frames:--}" "${p50:--}" "${p99:--}" "${max:--}" "${dropped:--}"
      rm -f "$out"
    done
  done
done
