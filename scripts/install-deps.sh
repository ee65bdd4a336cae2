#!/usr/bin/env bash
# Installs the Debian packages horus needs to build and test. Idempotent: installs only
# what is missing and runs `apt-get update` once, only when something is missing.
# Works as root on a fresh Debian 12 (uses sudo otherwise).
set -euo pipefail

packages=(
  g++ cmake ninja-build git pkg-config
  googletest libgtest-dev libgmock-dev libbenchmark-dev
  libfmt-dev libspdlog-dev nlohmann-json3-dev libeigen3-dev libcli11-dev
  libboost-dev   # boost::lockfree::spsc_queue, the benchmark baseline (header-only)
  libmsgpack-cxx-dev   # GenericMessage payloads (MessagePack)
  libdlpack-dev        # Tensor::to_dlpack (the DLPack ABI header)
  iceoryx libiceoryx-posh-dev   # iox-roudi and iceoryx 2.0: the baseline of horus-latency-shm
  cyclonedds-dev cyclonedds-tools   # the cyclonedds backend; idlc for the interop tests
  libfastrtps-dev libfastcdr-dev fastddsgen   # the fastdds backend; fastddsgen for the interop tests
  liblcm-dev liblcm-bin   # the lcm backend; lcm-gen, lcm-logger, lcm-logplayer for the interop tests
  libssl-dev   # libcrypto: horus security's keys, certificates and signed documents (security/)
  libyaml-cpp-dev   # HORUS_CONFIG: the per-topic configuration file (api/src/config.cpp)
  iproute2   # ip netns: the multi-host tests make hosts out of network namespaces
  nftables   # nft: the multi-host fault tests drop multicast and packets on namespace links
  libzstd-dev liblz4-dev zlib1g-dev   # MCAP recordings: zstd and lz4 chunks, CRC-32 (record/)
  nodejs   # the independent MCAP readers and Foxglove clients of the tests (tests/interop/*_js)
  chromium   # horus foxglove's status page in a real browser (puppeteer-core drives it headless)
  gnuplot-nox   # horus bench ping --plot: the latency histogram and CDF as PNG
  pybind11-dev python3-dev python3-numpy python3-pytest   # the Python package horus (python/) and its tests
  dpkg-dev lintian   # scripts/package.sh: the Debian packages (dpkg-shlibdeps) and their check
  python3-build python3-wheel python3-setuptools python3-venv unzip   # scripts/package.sh: the wheel, and the venvs that test it
  debootstrap   # scripts/package-test-debootstrap.sh (opt-in): the packages installed into a Debian 12 root
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# npm: Debian's, unless the installed Node.js ships its own (NodeSource's nodejs does, and
# conflicts with Debian's npm package).
if ! command -v npm >/dev/null; then missing+=(npm); fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages are installed"
else
  if [ -n "$sudo" ] && ! command -v sudo >/dev/null; then
    echo "install-deps: not root and no sudo; install: ${missing[*]}" >&2
    exit 1
  fi
  echo "install-deps: installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The npm packages of the tests' independent checkers (the MCAP readers, the Foxglove clients),
# at the versions their lock files pin; reinstalled only when a lock file changed.
root="$(cd "$(dirname "$0")/.." && pwd)"
for js in "$root/tests/interop/mcap_js" "$root/tests/interop/foxglove_js"; do
  stamp="$js/node_modules/.horus-lock-sha256"
  want="$(sha256sum "$js/package-lock.json" | cut -d' ' -f1)"
  if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
    echo "install-deps: npm ci in ${js#"$root"/}"
    (cd "$js" && npm ci --no-audit --no-fund --loglevel=error)
    echo "$want" > "$stamp"
  fi
done
