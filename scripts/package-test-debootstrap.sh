#!/usr/bin/env bash
# The Debian packages installed as a robot installs them (opt-in: it fetches Debian 12's
# packages from deb.debian.org; the CI's package test unpacks them instead, with dpkg -x):
#   scripts/package-test-debootstrap.sh [--build-dir DIR] [--keep]      (root)
# 1. a minimal Debian 12 root made by debootstrap in a new directory;
# 2. `apt-get install ./*.deb` of DIR/packages (scripts/package.sh makes them) inside it: apt
#    resolves the Depends the packages declare (Cyclone DDS, Fast DDS, LCM, ...) from Debian;
# 3. inside it: `horus --version`, `python3 -c "import horus"`, and a program built with
#    `pkg-config --cflags --libs horus` (g++ and pkg-config installed for it) that runs;
# 4. `apt-get purge` of the four packages: none of the files they installed is left.
# The root is removed at the end unless --keep.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=build/default
keep=0
while [[ $# -gt 0 ]]; do
  case $1 in
    --build-dir) dir=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "usage: $0 [--build-dir DIR] [--keep]" >&2; exit 2 ;;
  esac
done
[[ $(id -u) == 0 ]] || { echo "package-test-debootstrap.sh: needs root (debootstrap, chroot)" >&2; exit 1; }
command -v debootstrap >/dev/null || { echo "package-test-debootstrap.sh: no debootstrap (apt-get install debootstrap)" >&2; exit 1; }
shopt -s nullglob
debs=("$dir"/packages/*.deb)
[[ ${#debs[@]} -eq 4 ]] || { echo "package-test-debootstrap.sh: no packages in $dir/packages (scripts/package.sh)" >&2; exit 1; }

root=$(mktemp -d /tmp/horus-debootstrap.XXXXXX)
cleanup() {
  for m in proc dev/pts dev; do umount -l "$root/$m" 2>/dev/null || true; done
  if [[ $keep == 0 ]]; then rm -rf "$root"; else echo "kept $root"; fi
}
trap cleanup EXIT
echo "debootstrap: Debian 12 (bookworm, minbase) into $root"
debootstrap --variant=minbase bookworm "$root" http://deb.debian.org/debian >"$root.log" 2>&1 ||
  { tail -n 20 "$root.log" >&2; exit 1; }
mount -t proc proc "$root/proc"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mkdir -p "$root/pkgs"
cp "${debs[@]}" "$root/pkgs/"
cp tests/install/consumer/main.cpp "$root/pkgs/consumer.cpp"
in_root() { chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root DEBIAN_FRONTEND=noninteractive "$@"; }

in_root apt-get update -q >/dev/null
in_root sh -c 'apt-get install -y -q /pkgs/*.deb' >"$root.apt.log" 2>&1 || { tail -n 30 "$root.apt.log" >&2; exit 1; }
echo "installed: $(in_root dpkg-query -W -f='${Package} ${Version}\n' libhorus0 libhorus-dev horus-tools python3-horus | tr '\n' ' ')"
in_root horus --version
in_root python3 -c 'import horus; print("python3: horus", horus.__version__, "at", horus.__file__)'
in_root apt-get install -y -q g++ pkg-config >>"$root.apt.log" 2>&1
in_root sh -c 'c++ -O1 /pkgs/consumer.cpp -o /pkgs/consumer $(pkg-config --cflags --libs horus) && /pkgs/consumer'

# Purge: every file the packages installed is gone.
files=$(in_root dpkg -L libhorus0 libhorus-dev horus-tools python3-horus | sort -u)
in_root apt-get purge -y -q libhorus0 libhorus-dev horus-tools python3-horus >>"$root.apt.log" 2>&1
left=""
while read -r f; do
  [[ -n $f && -e $root$f && ! -d $root$f ]] && left+="$f"$'\n'
done <<<"$files"
[[ -z $left ]] || { echo "left after apt-get purge:"; echo "$left"; exit 1; } >&2
echo "purged: none of the packages' files is left"
rm -f "$root.log" "$root.apt.log"
