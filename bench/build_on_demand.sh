# Sourced by the benchmark scripts: builds the benchmark targets they run that every build does
# not (bench/CMakeLists.txt: EXCLUDE_FROM_ALL) in BUILD_DIR, quietly; a target whose generator
# was missing at configure time does not exist and is skipped (the script says what it lacks).
#   bench_build BUILD_DIR TARGET...
bench_build() {
  local dir="$1" t
  shift
  [ -f "$dir/build.ninja" ] || return 0
  for t in "$@"; do cmake --build "$dir" --target "$t" > /dev/null 2>&1 || true; done
}
