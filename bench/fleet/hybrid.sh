#!/usr/bin/env bash
# The hybrid promise of a fleet topic, whichever process holds the host's bridge: on namespace
# host A a publisher sends Pose2D at 1 kHz on a fleet topic and on a host topic; on A a
# subscriber of each, on host B a subscriber of the fleet topic, all blocked in recv_for
# (horus-fleet-hybrid, fleet/hybrid_latency.cpp). The fleet topic's bridge on A is held by the
# process that opened it first: the publisher, the local subscriber, or a third process.
# Needs root; nothing leaves this machine (a private bridge between the namespaces).
#
#   sudo bench/fleet/hybrid.sh [--rounds 3] [--backend all|cyclonedds|fastdds|lcm]
#                              [--holder all|publisher|subscriber|third] [--count 1500] [--build DIR]
#                              [--results FILE]
#
# --results FILE: one line per run, "backend holder round" then p50 p99 p99.9 (us) of the host
# subscriber, the fleet topic's local subscriber and the other host's ("-" for none): what
# scripts/bench.sh's report (bench/report.py) reads.
# Prints one line per run (p50/p99/p99.9 in us of the host subscriber, the fleet topic's local
# subscriber and the other host's), then per backend and holder the medians over rounds with
# their range, and the two ratios the regressions issue sets targets for: local fleet / host
# (<= 1.1) and other host / the publisher-holds-the-bridge case (<= 1.1).
set -euo pipefail
cd "$(dirname "$0")/../.."
rounds=3 backends="cyclonedds fastdds lcm" holders="publisher subscriber third" count=1500 build=build/default keep=""
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) rounds="$2"; shift 2 ;;
    --backend) [ "$2" = all ] || backends="$2"; shift 2 ;;
    --holder) [ "$2" = all ] || holders="$2"; shift 2 ;;
    --count) count="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --results) keep="$2"; shift 2 ;;
    *) echo "hybrid.sh: unknown argument '$1' (expected --rounds, --backend, --holder, --count, --build, --results)" >&2; exit 2 ;;
  esac
done
[ "$(id -u)" = 0 ] || { echo "hybrid.sh: needs root (namespace hosts)" >&2; exit 1; }
case $build in /*) ;; *) build="$PWD/$build" ;; esac
. bench/build_on_demand.sh
bench_build "$build" horus_fleet_hybrid
tool="$build/bench/horus-fleet-hybrid"
[ -x "$tool" ] || { echo "hybrid.sh: $tool is missing (cmake --build $build --target horus_fleet_hybrid)" >&2; exit 1; }
. scripts/lib/netns-hosts.sh
tmp=$(mktemp -d /tmp/horus-hybrid.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  nh_cleanup
  [ -n "${HYKEEP:-}" ] || rm -rf "$tmp"
}
trap cleanup EXIT
nh_create "hy$$" "10.216.$(( $$ % 250 + 1 ))" robot-a robot-b

# Waits (30 s at most) until FILE has a line starting with "ready".
wait_ready() {
  for _ in $(seq 600); do grep -q '^ready' "$1" 2>/dev/null && return 0; sleep 0.05; done
  echo "hybrid.sh: $1 did not get ready:" >&2
  cat "$1" "$1.err" >&2
  return 1
}
# start HOST OUT ARGS...: runs the tool on a host in the background, its output in OUT.
start() {
  local host=$1 out=$2
  shift 2
  nh_on "$host" env $env ${HYENV:-} timeout 120 "$tool" "$@" > "$out" 2> "$out.err" &
  pids+=("$!")
}

results="$tmp/results"
: > "$results"
printf "%-10s %-10s %5s | %-20s | %-20s | %-20s  (us: p50 p99 p99.9; Pose2D at 1 kHz, %s messages)\n" \
  backend holder round "host topic" "fleet, local sub" "fleet, other host" "$count"
for round in $(seq "$rounds"); do
  for b in $backends; do
    for h in $holders; do
      env="HORUS_CONFIG= HORUS_BACKEND=$b HORUS_DOMAIN_ID=$(( ($$ + round) % 200 + 1 )) HORUS_DDS_LOCALHOST=0
           HORUS_LCM_URL=udpm://239.255.76.$(( round % 200 + 10 )):$(( 20000 + $$ % 20000 ))?ttl=1"
      fleet="hy.r$round.$b.$h.fleet" host="hy.r$round.$b.$h.host" go="$tmp/go.$round.$b.$h"
      run="$tmp/$round.$b.$h"
      pids=()
      start 2 "$run.remote" sub --topic "$fleet" --fleet --count "$count" --label remote
      wait_ready "$run.remote"
      case $h in
        third)
          start 1 "$run.hold" hold --topic "$fleet" --seconds 100
          wait_ready "$run.hold" ;;
        publisher)
          start 1 "$run.pub" pub --fleet "$fleet" --host "$host" --count "$count" --go "$go"
          wait_ready "$run.pub" ;;
      esac
      start 1 "$run.local" sub --topic "$fleet" --fleet --count "$count" --label local
      wait_ready "$run.local"
      start 1 "$run.hostsub" sub --topic "$host" --count "$count" --label host
      wait_ready "$run.hostsub"
      if [ "$h" != publisher ]; then
        start 1 "$run.pub" pub --fleet "$fleet" --host "$host" --count "$count" --go "$go"
        wait_ready "$run.pub"
      fi
      touch "$go"
      for p in "${pids[@]}"; do
        if [ "$h" = third ] && [ "$p" = "${pids[1]}" ]; then continue; fi
        wait "$p" 2>/dev/null || true
      done
      [ "$h" = third ] && { kill "${pids[1]}" 2>/dev/null || true; wait "${pids[1]}" 2>/dev/null || true; }
      # Who held the bridge: the holder's ready line says bridge=1.
      holder_file="$run.pub"
      case $h in third) holder_file="$run.hold" ;; subscriber) holder_file="$run.local" ;; esac
      held=$(sed -n 's/^ready bridge=\([01]\).*/\1/p' "$holder_file" | head -1)
      line() { awk -v l="$1" '$1 == l {printf "%s %s %s", $2, $3, $4; found=1} END {if (!found) printf "- - -"}' "$run.$2"; }
      hs=$(line host hostsub) ls=$(line local local) rs=$(line remote remote)
      note=""
      [ "$held" = 1 ] || note=" (the $h did not hold the bridge)"
      # The bridge follows the host's publisher (fleet/README.md, the hand-over): who held it at the end.
      moved=$(sed -n 's/^sent [0-9]* bridge=\([01]\).*/\1/p' "$run.pub" | head -1)
      if [ "$h" != publisher ]; then
        if [ "$moved" = 1 ]; then note="$note (handed over to the publisher)"; else note="$note (not handed over)"; fi
      fi
      printf "%-10s %-10s %5s | %-20s | %-20s | %-20s%s\n" "$b" "$h" "$round" "$hs" "$ls" "$rs" "$note"
      echo "$b $h $round $hs $ls $rs" >> "$results"
    done
  done
done

[ -z "$keep" ] || cp "$results" "$keep"
echo
echo "medians over $rounds rounds (p50, us; min-max over rounds):"
python3 - "$results" <<'EOF'
import statistics, sys
rows = {}
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) < 12: continue
    b, h = f[0], f[1]
    def num(x):
        try: return float(x)
        except ValueError: return None
    rows.setdefault((b, h), []).append((num(f[3]), num(f[6]), num(f[9])))
def med(v):
    v = [x for x in v if x is not None]
    return (statistics.median(v), min(v), max(v)) if v else None
def fmt(m):
    return "-" if m is None else f"{m[0]:.1f} ({m[1]:.1f}-{m[2]:.1f})"
print(f"{'backend':<10} {'holder':<10} | {'host topic':<20} | {'fleet, local sub':<20} | {'fleet, other host':<20} | local/host  remote/(publisher holds)")
for (b, h), v in rows.items():
    host, local, remote = (med([r[i] for r in v]) for i in range(3))
    pub = rows.get((b, "publisher"))
    pub_remote = med([r[2] for r in pub]) if pub else None
    ratio_l = f"{local[0] / host[0]:.2f}" if host and local else "-"
    ratio_r = f"{remote[0] / pub_remote[0]:.2f}" if remote and pub_remote else "-"
    print(f"{b:<10} {h:<10} | {fmt(host):<20} | {fmt(local):<20} | {fmt(remote):<20} | {ratio_l:>9}  {ratio_r:>9}")
EOF
