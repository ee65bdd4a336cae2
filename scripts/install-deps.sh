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
  libyaml-cpp-dev   # HORUS_CONFIG: the per-topic configuration file (api/src/config.cpp)
  iproute2   # ip netns: the multi-host tests make hosts out of network namespaces
  libzstd-dev liblz4-dev   # MCAP recordings: zstd and lz4 chunk compression (record/)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages are installed"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: not root and no sudo; install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
