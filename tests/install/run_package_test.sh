#!/usr/bin/env bash
# The Debian packages as a robot installs them (issue 51), from the build directory BUILD:
#   tests/install/run_package_test.sh BUILD WORK
# 1. scripts/package.sh --no-build: the four packages, their Depends, lintian without error;
# 2. each unpacked (dpkg -x) into a fresh root WORK/root, as apt would put their files in /;
# 3. from the unpacked files only (LD_LIBRARY_PATH=root/usr/lib...): a project that uses
#    find_package(horus) and one built with `pkg-config --cflags --libs horus`, built and run;
#    the packaged `horus --version`; `python3 -c "import horus"` from the packaged module;
# 4. every file each package lists removed (what `dpkg --purge` removes): nothing is left;
# 5. the wheel installed with pip (no index) into a venv of Debian's python3 (NumPy from its
#    site-packages) and into a venv of another CPython 3.11 when there is one (`python3` on the
#    PATH, e.g. pyenv's), and imported from there.
# A real install into a Debian 12 root made by debootstrap (apt, dpkg -i, ldconfig, purge) is
# opt-in: scripts/package-test-debootstrap.sh.
set -euo pipefail
build=$(cd "$1" && pwd)
work=$2
here=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$work"
mkdir -p "$work/root"

"$here/scripts/package.sh" --no-build --build-dir "$build"
debs=("$build"/packages/*.deb)
for d in "${debs[@]}"; do dpkg-deb -x "$d" "$work/root"; done

root=$work/root
libdir=$(dirname "$(find "$root/usr/lib" -name 'libhorus.so.0' | head -n 1)")
[[ -e $libdir/libhorus.so.0 ]] || { echo "no libhorus.so.0 in the packages" >&2; exit 1; }
readelf -d "$libdir/libhorus.so.0" | grep -q 'SONAME.*\[libhorus\.so\.0\]' || { echo "libhorus.so.0 has no SONAME libhorus.so.0" >&2; exit 1; }
# The transports' plug-ins the build made, in libhorus0 beside the library (<libdir>/horus0), and
# libhorus.so.0 itself without the DDS libraries (a program loads them only with a plug-in).
for plugin in "$build"/horus0/libhorus-*.so; do
  [[ -e $plugin ]] || continue
  [[ -f $libdir/horus0/$(basename "$plugin") ]] || { echo "no $(basename "$plugin") in $libdir/horus0" >&2; exit 1; }
  echo "plug-in packaged: $libdir/horus0/$(basename "$plugin")"
done
if readelf -d "$libdir/libhorus.so.0" | grep -E 'NEEDED.*(libfastrtps|libddsc)'; then
  echo "libhorus.so.0 needs a DDS library (the DDS transports are plug-ins)" >&2
  exit 1
fi
export LD_LIBRARY_PATH=$libdir

# find_package(horus) from the packaged CMake files.
cmake -S "$here/tests/install/consumer" -B "$work/cmake" -G Ninja -DCMAKE_PREFIX_PATH="$root/usr" \
      -DCMAKE_BUILD_TYPE=Release >"$work/cmake.log" 2>&1 || { cat "$work/cmake.log" >&2; exit 1; }
cmake --build "$work/cmake" >>"$work/cmake.log" 2>&1 || { cat "$work/cmake.log" >&2; exit 1; }
out=$("$work/cmake/consumer")
[[ $out == *"received CmdVel linear=1.5"* ]] || { echo "the find_package consumer printed: $out" >&2; exit 1; }
echo "find_package consumer: $out"

# pkg-config from the packaged horus.pc.
flags=$(PKG_CONFIG_PATH=$libdir/pkgconfig pkg-config --cflags --libs horus)
echo "pkg-config --cflags --libs horus: $flags"
# shellcheck disable=SC2086
c++ -O1 "$here/tests/install/consumer/main.cpp" -o "$work/consumer_pc" $flags
out=$("$work/consumer_pc")
[[ $out == *"received CmdVel linear=1.5"* ]] || { echo "the pkg-config consumer printed: $out" >&2; exit 1; }
echo "pkg-config consumer: $out"

# The packaged CLI and Python module.
version=$("$root/usr/bin/horus" --version)
[[ $version == "horus "[0-9]* ]] || { echo "horus --version printed: $version" >&2; exit 1; }
echo "packaged CLI: $version"
site=$(dirname "$(dirname "$(find "$root/usr/lib" -name '_horus*.so' | head -n 1)")")
py=python3
[[ -x /usr/bin/python3 ]] && py=/usr/bin/python3
imported=$(cd "$work" && PYTHONPATH=$site PYTHONDONTWRITEBYTECODE=1 "$py" -c 'import horus; print(horus.__version__, horus.__file__)')
[[ $imported == *"$root"* ]] || { echo "python3 imported horus from elsewhere: $imported" >&2; exit 1; }
echo "packaged Python module: $imported"

# Uninstall: each package's files, as dpkg removes them; nothing else may be left.
for d in "${debs[@]}"; do
  dpkg-deb -c "$d" | awk '$1 !~ /^d/ {sub(/^\.\//, "", $6); print $6}' | while read -r f; do rm -f "$root/$f"; done
done
left=$(find "$root" ! -type d)
[[ -z $left ]] || { echo "files left after removing every packaged file:" >&2; echo "$left" >&2; exit 1; }
echo "removed: nothing is left in $root"

# The wheel, in venvs.
unset LD_LIBRARY_PATH
wheel=("$build"/packages/horus-*.whl)
[[ -f ${wheel[0]} ]] || { echo "no wheel in $build/packages" >&2; exit 1; }
"$py" -m venv --system-site-packages "$work/venv-debian"
"$work/venv-debian/bin/pip" install -q --no-index "${wheel[0]}"
got=$(cd "$work" && "$work/venv-debian/bin/python" -c 'import horus, numpy; print(horus.__version__, horus.__file__)')
[[ $got == *"$work/venv-debian/"* ]] || { echo "the Debian venv imported: $got" >&2; exit 1; }
echo "wheel in a venv of $("$py" --version): $got"
other=$(command -v python3 || true)
if [[ -n $other && $other != /usr/bin/python3 ]] && "$other" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then
  "$other" -m venv "$work/venv-other"
  # NumPy is declared; this interpreter may have none and no index is reachable: --no-deps.
  "$work/venv-other/bin/pip" install -q --no-index --no-deps "${wheel[0]}"
  got=$(cd "$work" && "$work/venv-other/bin/python" -c 'import horus; print(horus.__version__, horus.__file__)')
  [[ $got == *"$work/venv-other/"* ]] || { echo "the other interpreter's venv imported: $got" >&2; exit 1; }
  echo "wheel in a venv of $("$other" --version) ($other): $got"
fi
