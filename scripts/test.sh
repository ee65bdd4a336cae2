#!/usr/bin/env bash
# Sets up everything, builds, installs the Python package horus, and runs every test: the
# default build (all tests, the Python ones included), then the
# concurrency tests (and the LCM transport's threads) again under ThreadSanitizer, and the
# decoders of untrusted bytes (the local codec, the XCDR1 and LCM codecs, serialized topics, MCAP
# files and LCM logs, and every fuzz target's corpus and regression inputs) under
# AddressSanitizer + UBSan. HORUS_TEST_TSAN=0 / HORUS_TEST_ASAN=0 skip
# those passes.
#
# The default tests mostly wait (on processes, namespace hosts, networks): the sanitizer builds
# run meanwhile at the lowest CPU priority (nice 19), on the CPU the tests leave idle, their
# output in build/sanitizer-builds.log; their tests run after the default ones.
set -euo pipefail
self="$(cd "$(dirname "$0")" && pwd)/$(basename "$0")"
cd "$(dirname "$0")/.."
tsan=${HORUS_TEST_TSAN:-1}
asan=${HORUS_TEST_ASAN:-1}
tsan_targets=(test_ring_protocol test_topic_concurrency test_wait test_topic_serialized test_pool test_lcm_transport)
# The fuzz targets' corpora and regression inputs, replayed once each (fuzz/README.md).
replay=()
for t in $(sed -n 's/^set(HORUS_FUZZ_TARGETS \(.*\))$/\1/p' fuzz/CMakeLists.txt) lcm; do replay+=("fuzz_${t}_replay"); done
asan_targets=(test_codec test_cdr test_lcm_codec test_topic_serialized test_pool test_mcap test_ring "${replay[@]}")

jobs=$(nproc)
sanitizer_builds() {
  if [ "$tsan" != "0" ]; then
    cmake --preset tsan
    cmake --build --preset tsan -j "$jobs" --target "${tsan_targets[@]}"
  fi
  if [ "$asan" != "0" ]; then
    cmake --preset asan
    cmake --build --preset asan -j "$jobs" --target "${asan_targets[@]}"
  fi
}
# `test.sh --sanitizer-builds`: only the TSan and ASan builds of the targets above (what the
# test command runs in the background, in a process group of its own).
if [ "${1:-}" = "--sanitizer-builds" ]; then
  sanitizer_builds
  exit 0
fi

scripts/install-deps.sh

cmake --preset default
cmake --build --preset default -j "$jobs"
# The Python package into Debian's python3 (site-packages): `python3 -c "import horus"` works
# after this script; the tests below use the build tree's copy.
if [ -d build/default/python/horus ]; then
  cmake --install build/default --component python >/dev/null
  cmake --install build/default --component python_bundle >/dev/null
  py=python3
  [ -x /usr/bin/python3 ] && py=/usr/bin/python3
  (cd / && "$py" -c "import horus; print('python3: horus', horus.__version__, 'installed at', horus.__path__[0])")
fi

mkdir -p build
log=build/sanitizer-builds.log
san_pid=""
if [ "$tsan" != "0" ] || [ "$asan" != "0" ]; then
  setsid -w nice -n 19 "$self" --sanitizer-builds > "$log" 2>&1 < /dev/null &
  san_pid=$!
  # A failed or interrupted run takes the whole group (cmake, ninja, the compilers) down with it.
  trap 'if [ -n "$san_pid" ]; then kill -TERM -- "-$san_pid" 2>/dev/null || true; fi' EXIT
fi

# Two tests per CPU: most of the default tests wait (on processes, namespace hosts, networks),
# using about a quarter of the CPUs at one per CPU. The ones that compute (builds, packages, the
# recorder's benchmark, the three-host demo) take two slots each (PROCESSORS 2), so at most two of
# them share the CPUs, as at one test per CPU.
ctest --preset default -j "$((2 * jobs))"

if [ -n "$san_pid" ]; then
  if ! wait "$san_pid"; then
    san_pid=""
    echo "test.sh: the sanitizer builds failed:" >&2
    tail -n 60 "$log" >&2
    exit 1
  fi
  san_pid=""
  echo "test.sh: the sanitizer builds ran beside the tests ($log)"
fi

if [ "$tsan" != "0" ]; then
  # TSan needs the classic address-space layout; kernels with more mmap randomness break it.
  run=()
  if command -v setarch >/dev/null; then run=(setarch "$(uname -m)" -R); fi
  "${run[@]}" ctest --preset tsan -L concurrency
  "${run[@]}" ctest --preset tsan -R '^Lcm(Memq|File|Udpm)\.'
fi

if [ "$asan" != "0" ]; then
  ctest --preset asan -R '^(Codec|Cdr|LcmCodec|LcmEmitter|SerializedTopic|Pool|Backends/PoolTopic|Mcap|McapDamage|All/McapCompression|LcmLog|RingLayout)\.'
  ctest --preset asan -L '^fuzz$'
fi
