#!/usr/bin/env bash
# The fuzzing campaign (fuzz/README.md). Builds the libFuzzer targets with clang-19 into
# build/fuzz (installing clang-19 and libclang-rt-19-dev from Debian when they are missing),
# writes the seed corpora when fuzz/corpus lacks them, then runs each target for --seconds or
# --runs executions, whichever comes first, on a working copy of its corpus (what the fuzzer
# finds stays in build/fuzz/corpus/<target>); a crash is saved in build/fuzz/crashes/<target>/.
# Prints, per target: executions, executions per second, coverage (edges), corpus size, crashes;
# the table is also in build/fuzz/summary.txt.
#
#   scripts/fuzz.sh [--seconds 3600] [--runs 10000000] [--jobs 1] [--target NAME ...]
#
# Not part of the test command: CI replays the corpora and regression inputs under ASan+UBSan
# with the default compiler (ctest --preset asan -L fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=3600 runs=10000000 jobs=1 targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --target) targets+=("$2"); shift 2 ;;
    *) echo "fuzz.sh: unknown argument '$1' (expected --seconds, --runs, --jobs, --target)" >&2; exit 2 ;;
  esac
done
if ! command -v clang++-19 > /dev/null || [ ! -d /usr/lib/llvm-19/lib/clang/19/lib/linux ]; then
  [ "$(id -u)" = 0 ] || { echo "fuzz.sh: needs clang-19 and libclang-rt-19-dev (apt-get install them, or run as root)" >&2; exit 1; }
  apt-get update -q && apt-get install -y -q clang-19 libclang-rt-19-dev
fi
if [ ! -f build/fuzz/CMakeCache.txt ]; then
  CC=clang-19 CXX=clang++-19 cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DHORUS_FUZZ=ON -DHORUS_BUILD_TESTS=OFF \
    -DHORUS_BUILD_BENCHMARKS=OFF -DHORUS_BUILD_EXAMPLES=OFF
fi
all=$(sed -n 's/^set(HORUS_FUZZ_TARGETS \(.*\))$/\1/p' fuzz/CMakeLists.txt)
[ "${#targets[@]}" -gt 0 ] || { read -r -a targets <<< "$all"; targets+=(lcm); }
build=(fuzz_make_corpus)
for t in "${targets[@]}"; do build+=("fuzz_$t"); done
cmake --build build/fuzz -j "$(nproc)" --target "${build[@]}"
[ -d fuzz/corpus/local ] || build/fuzz/fuzz/fuzz_make_corpus fuzz/corpus
export HORUS_CONFIG= HORUS_LOG_LEVEL=off
summary=build/fuzz/summary.txt
printf "%-13s %12s %9s %8s %8s %8s  (%s s or %s runs each, %s)\n" target executions exec/s edges corpus crashes \
  "$seconds" "$runs" "$(date -u +%F)" | tee "$summary"
run_one() {
  local t="$1" work="build/fuzz/corpus/$1" crashes="build/fuzz/crashes/$1" log="build/fuzz/$1.log"
  mkdir -p "$work" "$crashes"
  local started="$work/.started"  # crashes of this run: files newer than this mark
  touch "$started"
  local extra=()
  [ -f "fuzz/$t.dict" ] && extra+=("-dict=fuzz/$t.dict")
  local max_len=65536
  [ "$t" = shm ] && max_len=524288  # a segment with a pool is 450 KiB
  "build/fuzz/fuzz/fuzz_$t" -max_total_time="$seconds" -runs="$runs" -max_len="$max_len" -rss_limit_mb=2048 \
    -timeout=10 -print_final_stats=1 -artifact_prefix="$crashes/" "${extra[@]}" "$work" "fuzz/corpus/$t" > "$log" 2>&1 || true
  local execs rate edges n crashed
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  edges=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  n=$(find "$work" -type f ! -name .started | wc -l)
  crashed=$(find "$crashes" -type f -newer "$started" | wc -l)  # not the ones of earlier runs, kept there
  printf "%-13s %12s %9s %8s %8s %8s\n" "$t" "${execs:-?}" "${rate:-?}" "${edges:-?}" "$n" "$crashed" | tee -a "$summary"
}
running=0
for t in "${targets[@]}"; do
  run_one "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then wait -n; running=$((running - 1)); fi
done
wait
echo "crashes (if any): build/fuzz/crashes/<target>/; logs: build/fuzz/<target>.log"
