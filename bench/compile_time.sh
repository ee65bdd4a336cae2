#!/usr/bin/env bash
# What a user's file costs to compile (issue 37's targets: <= 1.5 s and <= 3 s with g++ -O2):
#   bench/compile_time.sh [--base REF] [--rounds N]
# Compiles each file of bench/compile/ N times (default 5) as a find_package(horus) consumer does
# (g++ -std=c++23 -O2 -c, the installed include directories, the package's definitions):
#   topic_one_message.cpp  <horus/topic.hpp> and <horus/msg/geometry.hpp>: a Topic<Pose2D>
#   horus_all.cpp          <horus/horus.hpp>: the same node
# and prints, per file, the median and min-max wall time and the largest peak RSS. With --base, the
# same files are compiled against REF's headers too (a git worktree in a temp dir), interleaved
# with this tree's, round by round: the machine is shared, only same-run figures compare.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
rounds=5
base=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --rounds) rounds=$2; shift 2 ;;
    --base) base=$2; shift 2 ;;
    *) echo "usage: $0 [--base REF] [--rounds N]" >&2; exit 2 ;;
  esac
done
cxx=${CXX:-g++}
defs=(-DFMT_SHARED -DSPDLOG_COMPILED_LIB -DSPDLOG_FMT_EXTERNAL -DSPDLOG_SHARED_LIB -DHORUS_HAVE_CYCLONEDDS
      -DHORUS_HAVE_FASTDDS -DHORUS_HAVE_LCM)
work=$(mktemp -d)
trap 'rm -rf "$work"; if [[ -n $base ]]; then git -C "$here" worktree remove --force "$work/base" >/dev/null 2>&1 || true; fi' EXIT
trees=("$here")
labels=("this tree ($(git -C "$here" describe --always --dirty 2>/dev/null || echo '?'))")
if [[ -n $base ]]; then
  git -C "$here" worktree add --detach "$work/base" "$base" >/dev/null 2>&1
  trees+=("$work/base")
  labels+=("$base ($(git -C "$work/base" rev-parse --short HEAD))")
fi
compile() {  # tree file -> "seconds kB"
  local tree=$1 file=$2 incs=()
  for d in "$tree"/*/include; do incs+=(-I "$d"); done
  /usr/bin/time -f "%e %M" -o "$work/time" "$cxx" -std=c++23 -O2 "${defs[@]}" "${incs[@]}" -isystem /usr/include/eigen3 \
    -c "$here/bench/compile/$file" -o "$work/out.o"
  cat "$work/time"
}
declare -A secs rss
files=(topic_one_message.cpp horus_all.cpp)
for ((r = 1; r <= rounds; r++)); do
  for f in "${files[@]}"; do
    for i in "${!trees[@]}"; do
      read -r s m < <(compile "${trees[$i]}" "$f")
      secs[$i,$f]+="$s "
      (( m > ${rss[$i,$f]:-0} )) && rss[$i,$f]=$m
    done
  done
done
printf '%-24s %-36s %8s %15s %8s\n' file headers "median s" "min-max s" "RSS MB"
for f in "${files[@]}"; do
  for i in "${!trees[@]}"; do
    read -r med lo hi < <(tr ' ' '\n' <<<"${secs[$i,$f]}" | grep . | sort -n |
      awk '{v[NR] = $1} END {m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2; print m, v[1], v[NR]}')
    printf '%-24s %-36s %8.2f %7.2f-%-7.2f %8.0f\n' "$f" "${labels[$i]}" "$med" "$lo" "$hi" "$((rss[$i,$f] / 1024))"
  done
done
echo "targets: topic_one_message.cpp <= 1.5 s, horus_all.cpp <= 3 s ($cxx $($cxx -dumpversion), -O2, $rounds rounds)"
