#!/usr/bin/env bash
# Sets up everything, builds, installs the Python package horus, and runs every test: the
# default build (all tests, the Python ones included), then the
# concurrency tests (and the LCM transport's threads) again under ThreadSanitizer, and the
# decoders of untrusted bytes (the local codec, the XCDR1 and LCM codecs, serialized topics, MCAP
# files and LCM logs, and every fuzz target's corpus and regression inputs) under
# AddressSanitizer + UBSan. HORUS_TEST_TSAN=0 / HORUS_TEST_ASAN=0 skip
# those passes.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc)

cmake --preset default
cmake --build --preset default -j "$jobs"
# The Python package into Debian's python3 (site-packages): `python3 -c "import horus"` works
# after this script; the tests below use the build tree's copy.
if [ -d build/default/python/horus ]; then
  cmake --install build/default --component python >/dev/null
  py=python3
  [ -x /usr/bin/python3 ] && py=/usr/bin/python3
  (cd / && "$py" -c "import horus; print('python3: horus', horus.__version__, 'installed at', horus.__path__[0])")
fi
ctest --preset default -j "$jobs"

if [ "${HORUS_TEST_TSAN:-1}" != "0" ]; then
  cmake --preset tsan
  cmake --build --preset tsan -j "$jobs" --target test_ring_protocol test_topic_concurrency test_wait test_topic_serialized test_pool \
    test_lcm_transport
  # TSan needs the classic address-space layout; kernels with more mmap randomness break it.
  run=()
  if command -v setarch >/dev/null; then run=(setarch "$(uname -m)" -R); fi
  "${run[@]}" ctest --preset tsan -L concurrency
  "${run[@]}" ctest --preset tsan -R '^Lcm(Memq|File|Udpm)\.'
fi

if [ "${HORUS_TEST_ASAN:-1}" != "0" ]; then
  cmake --preset asan
  # The fuzz targets' corpora and regression inputs, replayed once each (fuzz/README.md).
  replay=()
  for t in $(sed -n 's/^set(HORUS_FUZZ_TARGETS \(.*\))$/\1/p' fuzz/CMakeLists.txt) lcm; do replay+=("fuzz_${t}_replay"); done
  cmake --build --preset asan -j "$jobs" --target test_codec test_cdr test_lcm_codec test_topic_serialized test_pool \
    test_mcap test_ring "${replay[@]}"
  ctest --preset asan -R '^(Codec|Cdr|LcmCodec|LcmEmitter|SerializedTopic|Pool|Backends/PoolTopic|Mcap|McapDamage|All/McapCompression|LcmLog|RingLayout)\.'
  ctest --preset asan -L '^fuzz$'
fi
