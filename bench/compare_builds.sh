#!/usr/bin/env bash
# Compares the local-path latency of two builds of horus in one run, alternating them:
#   bench/compare_builds.sh OLD_BUILD_DIR NEW_BUILD_DIR [ROUNDS]
# e.g. after `git worktree add /tmp/old <rev> && (cd /tmp/old && cmake --preset default &&
# cmake --build --preset default --target horus_latency_local horus_latency_shm)`:
#   bench/compare_builds.sh /tmp/old/build/default build/default 5
# Prints, per round and build: same-thread send+recv (ns/op, and boost's in the same process),
# cross-thread CmdVel p50 with its floor, cross-process CmdVel p50 with its floor; then the
# medians over rounds. The machine is shared: only same-run ratios and medians mean much.
set -euo pipefail
old=${1:?old build dir}
new=${2:?new build dir}
rounds=${3:-5}
declare -A all
# The floor's p50: the lowest over its rows (one line, two lines; older builds print one row).
floor_of() {
  awk '/^floor:/ {for (i = 2; i <= NF; i++) if ($i ~ /^[0-9]+\.[0-9]+$/) {if (best == "" || $i + 0 < best + 0) best = $i; break}}
       END {print best}'
}
row() {  # build label
  local dir=$1 label=$2
  local l s
  l=$("$dir/bench/horus-latency-local")
  s=$("$dir/bench/horus-latency-shm" --no-iceoryx)
  local same boost xt floor_t xp floor_p
  same=$(awk '/^horus Topic send\+recv/ {print $4}' <<<"$l")
  boost=$(awk '/^boost spsc_queue push\+pop/ {print $4}' <<<"$l")
  floor_t=$(floor_of <<<"$l")
  xt=$(awk '/^horus Topic<CmdVel>/ {print $3}' <<<"$l")
  floor_p=$(floor_of <<<"$s")
  xp=$(awk '/^horus Topic<CmdVel> \(16 B\)/ {print $5}' <<<"$s")
  printf '%-4s same-thread %6s ns (boost %5s) | cross-thread p50 %6s ns (floor %6s) | cross-process p50 %6s ns (floor %6s)\n' \
    "$label" "$same" "$boost" "$xt" "$floor_t" "$xp" "$floor_p"
  all[$label.same]+="$same "
  all[$label.xt]+="$xt "
  all[$label.xp]+="$xp "
}
median() { tr ' ' '\n' | grep -v '^$' | sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
for ((r = 1; r <= rounds; r++)); do
  echo "round $r"
  if ((r % 2)); then row "$old" old; row "$new" new; else row "$new" new; row "$old" old; fi
done
echo "medians over $rounds rounds (ns):"
for k in same xt xp; do
  printf '  %-28s old %8s   new %8s\n' \
    "$(case $k in same) echo 'same-thread send+recv';; xt) echo 'cross-thread CmdVel p50';; xp) echo 'cross-process CmdVel p50';; esac)" \
    "$(median <<<"${all[old.$k]}")" "$(median <<<"${all[new.$k]}")"
done
