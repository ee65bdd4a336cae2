#!/bin/bash
# `horus bench` between two namespace hosts (robot-a pings, robot-b answers), as a user runs it
# between two robots: each host its own network, /dev/shm and hostname (scripts/lib/netns-hosts.sh),
# on a private bridge (nothing leaves this machine). For each network backend: a Pose2D stream at
# 1 kHz, a Pose2D flood, and 1 MiB images at 30 Hz through the pool; then the same Pose2D
# stream between two processes of robot-a through shared memory. LCM gets recv_buf_size=4194304
# (an image is about 17 datagrams: the default socket buffer drops most of them). Runs `rounds` rounds and
# prints a table (median and range of the rounds' p50) into bench/results/cli_two_hosts.md,
# the summaries into cli_two_hosts.json, and the first round's Cyclone DDS plot into
# cli_two_hosts_cyclonedds.png. Needs root; uses the build's horus (build/default by default).
#
#   sudo bench/cli_two_hosts.sh [--build DIR] [--rounds N] [--duration S]
set -euo pipefail
cd "$(dirname "$0")/.."
build=build/default rounds=3 duration=5
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    --duration) duration="$2"; shift 2 ;;
    *) echo "usage: $0 [--build DIR] [--rounds N] [--duration S]" >&2; exit 2 ;;
  esac
done
[ "$(id -u)" = 0 ] || { echo "cli_two_hosts.sh: needs root (namespace hosts)" >&2; exit 1; }
horus="$PWD/$build/tools/horus"
[ -x "$horus" ] || { echo "cli_two_hosts.sh: $horus is missing; build first" >&2; exit 1; }
. scripts/lib/netns-hosts.sh
work="$(mktemp -d /tmp/horus-cli-bench.XXXXXX)"
out=bench/results
trap 'nh_cleanup; rm -rf "$work"' EXIT
nh_create "hcb$$" "10.216.$(( $$ % 250 + 1 ))" robot-a robot-b
env_for() {
  echo "HORUS_BACKEND=$1 HORUS_DOMAIN_ID=$(( $$ % 200 + 1 )) HORUS_DDS_LOCALHOST=0" \
       "HORUS_LCM_URL=udpm://239.255.76.70:$(( 20000 + $$ % 20000 ))?ttl=1&recv_buf_size=4194304 HORUS_CONFIG="
}

runs=()
one() {  # backend case round ping-args...
  local backend="$1" case="$2" round="$3"
  shift 3
  local json="$work/$backend.$case.$round.json" pong_host=2
  [ "$backend" = shm ] && pong_host=1
  # shellcheck disable=SC2046
  nh_on "$pong_host" env $(env_for "$backend") timeout 120 "$horus" bench pong --once >"$work/pong.log" 2>&1 &
  local pong=$!
  for _ in $(seq 200); do grep -q "answering on" "$work/pong.log" 2>/dev/null && break; sleep 0.05; done
  # shellcheck disable=SC2046
  if nh_on 1 env $(env_for "$backend") "$horus" bench ping -q --warmup 3 --json "$json" "$@" \
      >"$work/ping.log" 2>&1; then
    runs+=("$json")
    grep -E "^  (min|mean)|^messages|^throughput" "$work/ping.log" | sed "s/^/  $backend $case: /"
  else
    echo "  $backend $case: FAILED"; cat "$work/ping.log"
  fi
  # --once ends the pong after the run; a ping that failed before its hello leaves it waiting.
  for _ in $(seq 100); do kill -0 "$pong" 2>/dev/null || break; sleep 0.05; done
  pkill -TERM -f "timeout 120 $horus bench pong" 2>/dev/null || true  # timeout passes it on to the pong
  wait "$pong" 2>/dev/null || true
}

for round in $(seq "$rounds"); do
  echo "round $round"
  for backend in cyclonedds fastdds lcm; do
    plot=()
    [ "$round" = 1 ] && [ "$backend" = cyclonedds ] && plot=(--plot "$PWD/$out/cli_two_hosts_cyclonedds.png")
    one "$backend" pose_1khz "$round" --remote --type Pose2D --rate 1000 --duration "$duration" "${plot[@]}"
    one "$backend" pose_flood "$round" --remote --type Pose2D --flood --duration "$duration"
    one "$backend" image_1mib "$round" --remote --size 1048576 --rate 30 --duration "$duration"
  done
  one shm pose_1khz "$round" --type Pose2D --rate 1000 --duration "$duration"
done

/usr/bin/python3 - "$out" "${runs[@]}" <<'EOF'
import json, statistics, sys
out, files = sys.argv[1], sys.argv[2:]
rows = {}
for f in files:
    backend, case, _ = f.rsplit('/', 1)[1].rsplit('.', 3)[:3]
    j = json.load(open(f))
    rows.setdefault((backend, case), []).append(j)
json.dump([j for v in rows.values() for j in v], open(f"{out}/cli_two_hosts.json", "w"), indent=1)
def med(v): return f"{statistics.median(v):.1f} ({min(v):.1f}-{max(v):.1f})"
lines = ["| backend | traffic | one-way p50 us | p99 us | p99.9 us | lost / sent | msg/s | MB/s |",
         "|---|---|---|---|---|---|---|---|"]
for (backend, case), js in rows.items():
    ow = lambda k: [j["one_way_ns"][k] / 1e3 for j in js]
    lost = sum(j["lost"] for j in js); sent = sum(j["sent"] for j in js)
    lines.append(f"| {backend} | {case} | {med(ow('p50'))} | {med(ow('p99'))} | {med(ow('p99_9'))} | "
                 f"{lost} / {sent} | {statistics.median(j['throughput']['msgs_per_s'] for j in js):.0f} | "
                 f"{statistics.median(j['throughput']['mb_per_s'] for j in js):.2f} |")
text = "\n".join(lines) + f"\n\n{len(files)} runs; median (min-max) of the rounds' values.\n"
open(f"{out}/cli_two_hosts.md", "w").write(text)
print(text)
EOF
