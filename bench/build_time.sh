#!/usr/bin/env bash
# What the build costs, from ninja's log (issue 51's targets: compiler CPU of the default build
# <= 1300 s, scripts/test.sh from a fresh clone <= 20 minutes on 2 cores):
#   bench/build_time.sh [BUILD_DIR]                 reads BUILD_DIR/.ninja_log (build/default)
#   bench/build_time.sh --fresh [--jobs N] [--keep] configures and builds the default preset in a
#                                                   new directory first, timing it (N: nproc)
# Prints the wall time (measured with --fresh; else the span of the log's last build), the sum of
# the compile units' times (the compiler CPU a fresh build spends), the links' sum, and the 20
# slowest units. Without --fresh, a directory built several times is read as its last build, the
# units that build did not redo taken from the builds before (each unit once, as a fresh build
# compiles it): the sum then mixes figures taken under other loads, and the wall time is unknown.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
fresh=0
keep=0
jobs=$(nproc)
dir=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --fresh) fresh=1; shift ;;
    --jobs) jobs=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    -*) echo "usage: $0 [--fresh [--jobs N] [--keep]] [BUILD_DIR]" >&2; exit 2 ;;
    *) dir=$1; shift ;;
  esac
done
wall=""
if [[ $fresh == 1 ]]; then
  dir=$(mktemp -d /tmp/horus-build-time.XXXXXX)
  (cd "$here" && cmake --preset default -B "$dir" >/dev/null)
  start=$(date +%s.%N)
  cmake --build "$dir" -j "$jobs" >"$dir/build.log" 2>&1 || { tail -n 30 "$dir/build.log" >&2; exit 1; }
  wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {printf "%.0f", b - a}')
  echo "built the default preset in $dir with -j $jobs"
fi
dir=${dir:-$here/build/default}
log=$dir/.ninja_log
[[ -f $log ]] || { echo "build_time.sh: no $log (build first, or --fresh)" >&2; exit 1; }
[[ $(head -n 1 "$log") == "# ninja log v"* ]] || { echo "build_time.sh: $log is not a ninja log" >&2; exit 1; }

# Fields: start end mtime output hash (ms). Within one build the entries come in order of their
# end; a build that starts again from 0 is a new build. Each output counts once (its last entry).
units_file=$(mktemp)
trap 'rm -f "$units_file"; if [[ $fresh == 1 && $keep == 0 ]]; then rm -rf "$dir"; fi' EXIT
awk -v wall="$wall" -v fresh="$fresh" -v units_file="$units_file" '
  NR == 1 { next }
  {
    if (NR > 2 && $2 + 1000 < prev_end) { builds++; last_start = 0; last_end = 0; first_of_last = 1 }
    prev_end = $2
    t[$4] = ($2 - $1) / 1000.0
    if (first_of_last || NR == 2) { span_start = $1; first_of_last = 0 }
    if ($1 < span_start) span_start = $1
    span_end = $2
  }
  END {
    units = 0; cpu = 0; links = 0; nlinks = 0
    for (o in t) {
      if (o ~ /\.o$/) { units++; cpu += t[o]; printf "%.1f %s\n", t[o], o > units_file }
      else { nlinks++; links += t[o] }
    }
    if (fresh == 1) printf "wall time: %s s\n", wall
    else if (builds == 0) printf "wall time: %.0f s (the span of the log: one build)\n", (span_end - span_start) / 1000.0
    else printf "wall time: unknown (%d builds in the log; --fresh measures one)\n", builds + 1
    printf "compile units: %d, their sum: %.0f s (target <= 1300 s)\n", units, cpu
    printf "links and other steps: %d, their sum: %.0f s\n", nlinks, links
    printf "the 20 slowest units (s):\n"
  }' "$log"
sort -rn "$units_file" | head -n 20 | awk '{printf "  %7.1f  %s\n", $1, $2}'
