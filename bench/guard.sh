#!/usr/bin/env bash
# The regression guard: builds BASE_REF in a git worktree and compares it with this tree's build in
# one interleaved run (base and HEAD alternate round by round, so the machine's drift hits both):
#
#   bench/guard.sh BASE_REF [--rounds 5] [--no-hybrid] [--build build/default]
#
#   same-thread      Topic send+recv (ns), its ratio to boost::lockfree::spsc_queue's in the same process
#   cross-thread     CmdVel p50 (ns), its ratio to the true floor of its run (cache_floor.hpp)
#   cross-process    CmdVel p50 (ns), its ratio to the true floor of its run
#   hybrid local     a fleet topic's local subscriber p50 / a host topic's, the bridge held by the
#                    subscriber process, Cyclone DDS, two namespace hosts (fleet/hybrid.sh; root)
#   recorder idle    `horus record` of a 10 Hz topic for 3 s: CPU used, % of one core
#
# Prints every round, then the medians, base against HEAD, and exits 1 when HEAD is worse than
# the base on a row by more than the noise: its median over the rounds more than 10% above the
# base's (the recorder: above the base's and above 1% of a core; a latency ratio: its ns too,
# since a ratio whose ns did not move only says the floor of its rounds moved). Run it before
# resolving an issue that touches api/, backend_shm/, fleet/ or record/ (bench/README.md), and
# quote its table.
# The base's worktree and build are kept in ${HORUS_GUARD_DIR:-/tmp/horus-guard}/<sha> for the
# next run. A base older than a tool the guard runs gets HEAD's source of that tool (the hybrid
# latency tool) built against it: the measured code is the base's library.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
base_ref="" rounds=5 hybrid=1 head_build=build/default
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) rounds="$2"; shift 2 ;;
    --no-hybrid) hybrid=0; shift ;;
    --build) head_build="$2"; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    -*) echo "guard.sh: unknown option '$1'" >&2; exit 2 ;;
    *) [ -z "$base_ref" ] || { echo "guard.sh: one BASE_REF only" >&2; exit 2; }; base_ref="$1"; shift ;;
  esac
done
[ -n "$base_ref" ] || { echo "usage: bench/guard.sh BASE_REF [--rounds 5] [--no-hybrid] [--build DIR]" >&2; exit 2; }
sha=$(git rev-parse --verify --quiet "$base_ref^{commit}") || { echo "guard.sh: '$base_ref' is not a commit" >&2; exit 2; }
case $head_build in /*) ;; *) head_build="$root/$head_build" ;; esac
gdir=${HORUS_GUARD_DIR:-/tmp/horus-guard}/${sha:0:12}
targets=(horus_latency_local horus_latency_shm horus_cli)
if [ "$hybrid" = 1 ] && [ "$(id -u)" != 0 ]; then
  echo "guard.sh: not root: the hybrid row (namespace hosts) is skipped"
  hybrid=0
fi
[ "$hybrid" = 1 ] && targets+=(horus_fleet_hybrid)

# The base: a worktree at BASE_REF, and HEAD's source of the tools it lacks.
if [ ! -d "$gdir/src" ]; then
  mkdir -p "$gdir"
  git worktree add --detach "$gdir/src" "$sha" > /dev/null
fi
if [ "$hybrid" = 1 ] && ! grep -q horus_fleet_hybrid "$gdir/src/bench/CMakeLists.txt"; then
  mkdir -p "$gdir/src/bench/fleet"
  cp bench/fleet/hybrid_latency.cpp "$gdir/src/bench/fleet/"
  [ -f "$gdir/src/bench/bench_common.hpp" ] || cp bench/bench_common.hpp "$gdir/src/bench/"
  cat >> "$gdir/src/bench/CMakeLists.txt" <<'EOF'
# Added by bench/guard.sh (HEAD's tool, built against this revision's library).
add_executable(horus_fleet_hybrid EXCLUDE_FROM_ALL fleet/hybrid_latency.cpp)
set_target_properties(horus_fleet_hybrid PROPERTIES OUTPUT_NAME horus-fleet-hybrid)
target_include_directories(horus_fleet_hybrid PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
target_link_libraries(horus_fleet_hybrid PRIVATE horus::horus CLI11::CLI11 fmt::fmt)
EOF
fi
echo "guard.sh: building the base ${sha:0:12} in $gdir/build (${targets[*]})"
cmake -S "$gdir/src" -B "$gdir/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DHORUS_BUILD_TESTS=OFF -DHORUS_BUILD_EXAMPLES=OFF -DHORUS_BUILD_PYTHON=OFF > "$gdir/configure.log" 2>&1 ||
  { tail -20 "$gdir/configure.log" >&2; exit 1; }
cmake --build "$gdir/build" -j "$(nproc)" --target "${targets[@]}" > "$gdir/build.log" 2>&1 ||
  { tail -30 "$gdir/build.log" >&2; exit 1; }
echo "guard.sh: building HEAD in $head_build (${targets[*]})"
cmake --build "$head_build" -j "$(nproc)" --target "${targets[@]}" > "$gdir/head-build.log" 2>&1 ||
  { tail -30 "$gdir/head-build.log" >&2; exit 1; }

base_dir="$gdir/build"
declare -A all
add() { all[$1]+="$2 "; }
floor_of() {  # the true floor's p50: the lowest over its rows
  awk '/^floor:/ {for (i = 2; i <= NF; i++) if ($i ~ /^[0-9]+\.[0-9]+$/) {if (best == "" || $i + 0 < best + 0) best = $i; break}}
       END {print best}'
}
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {if (a == "" || b == "" || b + 0 == 0) print "-"; else printf "%.2f", a / b}'; }

local_rows() {  # DIR LABEL
  local dir=$1 label=$2 l s same boost xt ft xp fp
  l=$("$dir/bench/horus-latency-local" 2>/dev/null)
  s=$("$dir/bench/horus-latency-shm" --no-iceoryx 2>/dev/null)
  same=$(awk '/^horus Topic send\+recv/ {print $4}' <<<"$l")
  boost=$(awk '/^boost spsc_queue push\+pop/ {print $4}' <<<"$l")
  xt=$(awk '/^horus Topic<CmdVel>/ {print $3}' <<<"$l")
  ft=$(floor_of <<<"$l")
  xp=$(awk '/^horus Topic<CmdVel> \(16 B\)/ {print $5}' <<<"$s")
  fp=$(floor_of <<<"$s")
  add "$label.same" "$(ratio "$same" "$boost")"
  add "$label.xt" "$(ratio "$xt" "$ft")"
  add "$label.xp" "$(ratio "$xp" "$fp")"
  add "$label.same_ns" "$same"
  add "$label.xt_ns" "$xt"
  add "$label.xp_ns" "$xp"
  printf '  %-4s same-thread %5s ns (boost %4s) | cross-thread %6s ns (floor %6s) | cross-process %6s ns (floor %6s)\n' \
    "$label" "$same" "$boost" "$xt" "$ft" "$xp" "$fp"
}

hybrid_row() {  # DIR LABEL
  local dir=$1 label=$2 out r
  out=$(bench/fleet/hybrid.sh --rounds 1 --backend cyclonedds --holder subscriber --count 1000 --build "$dir" 2>&1) || true
  r=$(awk '$1 == "cyclonedds" && $2 == "subscriber" && $3 == "|" {print $(NF-1)}' <<<"$out" | tail -1)
  if [ -z "$r" ] || [ "$r" = "-" ]; then
    echo "  $label hybrid: no result:"; tail -5 <<<"$out" | sed 's/^/    /'
    return
  fi
  add "$label.hybrid" "$r"
  printf '  %-4s hybrid: fleet topic local subscriber / host topic p50 = %s (%s)\n' "$label" "$r" \
    "$(awk '$1 == "cyclonedds" && $2 == "subscriber" && $3 == "1" {print "host", $5, "us, fleet local", $9, "us"}' <<<"$out")"
}

recorder_row() {  # DIR LABEL
  local dir=$1 label=$2 cli="$1/tools/horus" topic="guard.r$$.$2" file pub t pct
  file=$(mktemp -u /tmp/horus-guard-rec.XXXXXX.mcap)
  "$cli" topic pub "$topic" Pose2D '{"x": 1}' --rate 10 > /dev/null 2>&1 &
  pub=$!
  sleep 0.5
  # The shell's `times`: its children's user and system time (the recorder's, here).
  t=$( { "$cli" record -o "$file" --topics "$topic" --duration 3 > /dev/null 2>&1 || true; times; } | tail -1)
  kill "$pub" 2> /dev/null || true
  wait "$pub" 2> /dev/null || true
  rm -f "$file"
  pct=$(awk '{split($1, u, /[ms]/); split($2, s, /[ms]/); printf "%.2f", (u[1] * 60 + u[2] + s[1] * 60 + s[2]) / 3 * 100}' <<<"$t")
  add "$label.rec" "$pct"
  printf '  %-4s recorder: %s%% of a core recording a 10 Hz topic for 3 s\n' "$label" "$pct"
}

for ((r = 1; r <= rounds; r++)); do
  echo "round $r"
  if ((r % 2)); then order=("$base_dir base" "$head_build head"); else order=("$head_build head" "$base_dir base"); fi
  for kind in local_rows recorder_row $([ "$hybrid" = 1 ] && echo hybrid_row); do
    for o in "${order[@]}"; do $kind $o; done
  done
done

median() { tr ' ' '\n' | grep -Ev '^(|-)$' | sort -g | awk '{a[NR]=$1} END {if (NR == 0) print "-"; else print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
echo
echo "medians over $rounds rounds, base ${sha:0:12} ($base_ref) against HEAD $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- . ':!bench/results' || echo ' + uncommitted changes'):"
printf '  %-44s %12s %12s %8s  %s\n' "" base HEAD change verdict
worse=0
row() {  # key label [absolute floor under which HEAD passes] [key of the row's ns]
  local key=$1 label=$2 floor=${3:-0} ns_key=${4:-} b h change verdict
  b=$(median <<<"${all[base.$key]:-}")
  h=$(median <<<"${all[head.$key]:-}")
  if [ "$b" = "-" ] || [ "$h" = "-" ]; then
    printf '  %-44s %12s %12s %8s  %s\n' "$label" "$b" "$h" "-" "not measured"
    return
  fi
  change=$(awk -v b="$b" -v h="$h" 'BEGIN {if (b + 0 == 0) print "-"; else printf "%+.0f%%", (h / b - 1) * 100}')
  verdict=$(awk -v b="$b" -v h="$h" -v f="$floor" 'BEGIN {print (h > b * 1.10 && h > f) ? "WORSE" : "ok"}')
  # A latency ratio whose ns did not grow: only the floor of its rounds moved (this VM's floor
  # is bimodal), not the path. Worse only when the ns are worse by more than 10% too.
  if [ "$verdict" = WORSE ] && [ -n "$ns_key" ]; then
    local bn hn
    bn=$(median <<<"${all[base.$ns_key]:-}")
    hn=$(median <<<"${all[head.$ns_key]:-}")
    verdict=$(awk -v b="$bn" -v h="$hn" 'BEGIN {print (h > b * 1.10) ? "WORSE" : "ok (the ns did not grow: the floor moved)"}')
  fi
  [[ $verdict == ok* ]] || worse=1
  printf '  %-44s %12s %12s %8s  %s\n' "$label" "$b" "$h" "$change" "$verdict"
}
info() {  # key label: shown, not judged (the ratio is)
  printf '  %-44s %12s %12s\n' "$1" "$(median <<<"${all[base.$2]:-}")" "$(median <<<"${all[head.$2]:-}")"
}
row same "same-thread send+recv / boost" 0 same_ns
info "  same-thread send+recv (ns)" same_ns
row xt "cross-thread CmdVel p50 / true floor" 0 xt_ns
info "  cross-thread CmdVel p50 (ns)" xt_ns
row xp "cross-process CmdVel p50 / true floor" 0 xp_ns
info "  cross-process CmdVel p50 (ns)" xp_ns
[ "$hybrid" = 1 ] && row hybrid "hybrid: fleet local sub p50 / host topic p50"
row rec "recorder idle CPU (% of a core, 10 Hz topic)" 1
if [ "$worse" = 1 ]; then
  echo "guard.sh: HEAD is worse than ${sha:0:12} by more than 10% on a row above"
  exit 1
fi
echo "guard.sh: no row worse than ${sha:0:12} by more than 10%"
