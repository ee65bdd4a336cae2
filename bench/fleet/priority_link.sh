#!/usr/bin/env bash
# A saturated link between two namespace hosts: can a 30 Hz camera delay the fleet's small,
# periodic topics? On the robot host, three processes publish: a camera (30 Hz, side x side
# mono8 frames: more than the link carries), a 50 Hz Pose2D and a 10 Hz Pose2D (a heartbeat's
# stand-in: horus's own heartbeats go at high priority too). The robot host's egress is a tc
# tbf of --rate with a --queue of buffering (what a Wi-Fi driver holds). The other host
# receives all three and reports the age of each message (one machine, one clock).
#
# Three modes per round: "none" (no budget: every frame goes, the link's queue fills), "flat"
# (network.max_bandwidth --budget on the robot host, every topic at the default priority) and
# "link" (the same budget, camera at priority low, poses at high: the host's bridges never book
# the link more than 10 ms ahead for the camera, and the poses always go).
#
#   sudo bench/fleet/priority_link.sh [--rate 20mbit] [--queue 200ms] [--budget "2 MB/s"] [--side 320]
#                                     [--seconds 8] [--rounds 2] [--backend all|cyclonedds|fastdds|lcm]
#
# Prints per backend, mode and round: frames received and the age p50 / p99 / max in ms of the
# camera, the 50 Hz pose and the 10 Hz pose. Needs root; nothing leaves this machine.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=8 rate=20mbit rounds=2 backends="cyclonedds fastdds lcm" build=build/default budget="2 MB/s" queue=200ms side=320
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    --backend) [ "$2" = all ] || backends="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --budget) budget="$2"; shift 2 ;;
    --queue) queue="$2"; shift 2 ;;
    --side) side="$2"; shift 2 ;;
    *) echo "priority_link.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ "$(id -u)" = 0 ] || { echo "priority_link.sh: needs root (namespace hosts)" >&2; exit 1; }
. bench/build_on_demand.sh
bench_build "$build" horus_slow_link_image
prog="$PWD/$build/bench/horus-slow-link-image"
[ -x "$prog" ] || { echo "priority_link.sh: $prog is missing; build the benchmarks first" >&2; exit 1; }
. scripts/lib/netns-hosts.sh
config="$(mktemp /tmp/horus-priority-link.XXXXXX.yaml)" flat="$(mktemp /tmp/horus-priority-flat.XXXXXX.yaml)"
trap 'nh_cleanup; rm -f "$config" "$flat"' EXIT
# Fresh hosts for every run: what one run leaves on a host (its /dev/shm, the remote side's
# discovery state) must not weigh on the next (seen: Fast DDS frames after an unpaced run).
fresh_hosts() {
  nh_cleanup
  nh_create "pl$$" "10.215.$(( $$ % 250 + 1 ))" robot base
  ip -n "${nh_prefix}h1" link set eth0 txqueuelen 1000
  tc -n "${nh_prefix}h1" qdisc replace dev eth0 root tbf rate "$rate" burst 32kb latency "$queue"
}
printf 'network:\n  max_bandwidth: "%s"\ntopics:\n  - match: "fleet.camera.**"\n    priority: low\n  - match: "fleet.pose.**"\n    priority: high\n' \
  "$budget" > "$config"
printf 'network:\n  max_bandwidth: "%s"\n' "$budget" > "$flat"
printf "camera %sx%s mono8 at 30 Hz (%s kB/s) over %s with a %s queue; link budget %s\n" "$side" "$side" \
  "$(( side * side * 30 / 1000 ))" "$rate" "$queue" "$budget"
printf "%-11s %-5s %2s | %6s %7s %7s %7s | %5s %7s %7s %7s | %5s %7s %7s %7s\n" backend mode r \
  cam_n p50_ms p99_ms max_ms pose50 p50_ms p99_ms max_ms pose10 p50_ms p99_ms max_ms
row() {  # reads "frames N age_ms p50 P p99 Q max M dropped D"
  local n p50 p99 max
  read -r _ n _ _ p50 _ p99 _ max _ < "$1" || true
  printf "%5s %7s %7s %7s" "${n:--}" "${p50:--}" "${p99:--}" "${max:--}"
}
for round in $(seq "$rounds"); do
  for b in $backends; do
    for mode in none flat link; do
      fresh_hosts
      env="HORUS_BACKEND=$b HORUS_DOMAIN_ID=$(( $$ % 200 + 1 )) HORUS_DDS_LOCALHOST=0 HORUS_LCM_URL=udpm://239.255.76.71:$(( 20000 + $$ % 20000 ))?ttl=1&recv_buf_size=8388608"
      [ "$mode" = link ] && env="HORUS_CONFIG=$config $env"
      [ "$mode" = flat ] && env="HORUS_CONFIG=$flat $env"
      tag="${round}_${b}_$mode"
      cam="$(mktemp)" p50="$(mktemp)" p10="$(mktemp)"
      nh_on 2 env $env "$prog" sub "fleet.camera.$tag" $(( seconds + 4 )) > "$cam" 2>/dev/null &
      s1=$!
      nh_on 2 env $env "$prog" pose-sub "fleet.pose.fast.$tag" $(( seconds + 4 )) > "$p50" 2>/dev/null &
      s2=$!
      nh_on 2 env $env "$prog" pose-sub "fleet.pose.slow.$tag" $(( seconds + 4 )) > "$p10" 2>/dev/null &
      s3=$!
      sleep 2
      nh_on 1 env $env "$prog" pose-pub "fleet.pose.fast.$tag" 50 "$seconds" > /dev/null 2>&1 &
      p1=$!
      nh_on 1 env $env "$prog" pose-pub "fleet.pose.slow.$tag" 10 "$seconds" > /dev/null 2>&1 &
      p2=$!
      nh_on 1 env $env "$prog" pub "fleet.camera.$tag" 30 "$seconds" "$side" > /dev/null 2>&1 || true
      wait "$p1" "$p2" "$s1" "$s2" "$s3" || true
      printf "%-11s %-5s %2s | %s | %s | %s\n" "$b" "$mode" "$round" "$(row "$cam")" "$(row "$p50")" "$(row "$p10")"
      rm -f "$cam" "$p50" "$p10"
    done
  done
done
