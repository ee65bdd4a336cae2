#!/usr/bin/env bash
# The Debian packages of horus (packaging/README.md), from a build of the default preset (built
# first when it is not; its library, CLI and Python module are what the packages hold):
#   libhorus0      libhorus.so.0 (the library, its transports and the 81 standard messages)
#   libhorus-dev   headers, CMake package (find_package(horus)), horus.pc, horus-idlgen, IDL/LCM files
#   horus-tools    the horus command line and its bash completion
#   python3-horus  the module horus for Debian's python3
# and the Python wheel horus-<version>-cp311-cp311-linux_x86_64.whl (packaging/python: the module
# and libhorus.so.0 beside it, NumPy declared; `pip install` it into a venv or another CPython
# 3.11), made with Debian's python3-build (`python3 -m build --no-isolation`: no index needed).
#
#   scripts/package.sh [--build-dir DIR] [--no-build] [--no-lintian] [--no-wheel]
#
# The packages land in DIR/packages (DIR: build/default). Each declares the Debian packages its
# files link (dpkg-shlibdeps), so `apt install ./DIR/packages/*.deb` on a robot pulls what is
# missing. lintian checks each; an error fails the script (warnings are printed).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=build/default
build=1
lint=1
wheel=1
while [[ $# -gt 0 ]]; do
  case $1 in
    --build-dir) dir=$2; shift 2 ;;
    --no-build) build=0; shift ;;
    --no-lintian) lint=0; shift ;;
    --no-wheel) wheel=0; shift ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) echo "usage: $0 [--build-dir DIR] [--no-build] [--no-lintian] [--no-wheel]" >&2; exit 2 ;;
  esac
done

if [[ $build == 1 ]]; then
  if [[ ! -f $dir/CMakeCache.txt ]]; then cmake --preset default -B "$dir"; fi
  cmake --build "$dir" -j "$(nproc)" --target horus_shared horus_cli horus_python horus-idlgen horus-msg-catalogue
fi
[[ -f $dir/CPackConfig.cmake ]] || { echo "package.sh: $dir has no CPackConfig.cmake (a build with HORUS_SHARED=ON makes it)" >&2; exit 1; }
rm -rf "$dir/packages"
# Into /usr, whatever prefix the build was configured for.
(cd "$dir" && cpack -G DEB -D CPACK_PACKAGING_INSTALL_PREFIX=/usr) >"$dir/cpack.log" 2>&1 ||
  { tail -n 40 "$dir/cpack.log" >&2; exit 1; }
shopt -s nullglob
debs=("$dir"/packages/*.deb)
[[ ${#debs[@]} -eq 4 ]] || { echo "package.sh: expected 4 packages in $dir/packages, found ${#debs[@]}" >&2; exit 1; }
for d in "${debs[@]}"; do
  echo "$(basename "$d"): $(dpkg-deb -f "$d" Depends)"
done

# lintian checks the packages while the wheel builds.
lint_pid=""
if [[ $lint == 1 ]]; then
  if ! command -v lintian >/dev/null; then
    echo "package.sh: no lintian (scripts/install-deps.sh installs it); the packages are not checked" >&2
    exit 1
  fi
  # Errors fail; warnings and notes are shown. (--fail-on error: lintian >= 2.105.)
  lintian --fail-on error --no-tag-display-limit "${debs[@]}" >"$dir/lintian.log" 2>&1 &
  lint_pid=$!
  trap 'if [[ -n $lint_pid ]]; then kill "$lint_pid" 2>/dev/null || true; fi' EXIT
fi

if [[ $wheel == 1 ]]; then
  py=python3
  [[ -x /usr/bin/python3 ]] && py=/usr/bin/python3  # Debian's, with python3-build
  HORUS_BUILD_DIR=$(cd "$dir" && pwd) "$py" -m build --no-isolation --wheel --outdir "$dir/packages" packaging/python \
    >"$dir/wheel.log" 2>&1 || { tail -n 30 "$dir/wheel.log" >&2; exit 1; }
  rm -rf packaging/python/build packaging/python/stage packaging/python/*.egg-info
  echo "$(basename "$dir"/packages/horus-*.whl): $(unzip -p "$dir"/packages/horus-*.whl '*.dist-info/METADATA' | grep '^Requires-Dist' | tr '\n' ' ')"
fi

if [[ -n $lint_pid ]]; then
  rc=0
  wait "$lint_pid" || rc=$?
  lint_pid=""
  if [[ $rc == 0 ]]; then
    cat "$dir/lintian.log"
    echo "package.sh: lintian reports no error"
  else
    cat "$dir/lintian.log" >&2
    echo "package.sh: lintian reports errors (above)" >&2
    exit 1
  fi
fi
