#!/usr/bin/env bash
# The fleet demo across three hosts made of namespaces (needs root): robot hosts 1 and 2 each
# run a driver (pose, heartbeat and transform on fleet scope, a 640x480 camera on host scope)
# and a planner that reads them locally; host 3 runs the monitor. Each host has its own network
# namespace on a private bridge (nothing leaves this machine), its own /dev/shm and hostname.
# The scopes come from examples/fleet.yaml (HORUS_CONFIG), not from code. A third of the way in,
# robot2's link goes down for a while (a robot out of Wi-Fi range): the monitor's horus::Fleet
# reports it lost after 3 missed heartbeats, then rejoined; at the end `horus fleet --once` shows
# the fleet from the monitor's host.
#
# With --python the monitor host runs the Python monitor (examples/python/monitor.py) instead:
# the same topics, scopes and configuration file, from Python.
#
#   sudo scripts/fleet-demo.sh [--backend cyclonedds|fastdds|lcm] [--duration 10] [--no-cut] [--no-build] [--python]
set -euo pipefail
cd "$(dirname "$0")/.."
backend=cyclonedds
duration=10
build=1
cut=1
python=0
while [ $# -gt 0 ]; do
  case "$1" in
    --backend) backend="$2"; shift 2 ;;
    --duration) duration="$2"; shift 2 ;;
    --no-build) build=0; shift ;;
    --no-cut) cut=0; shift ;;
    --python) python=1; shift ;;
    *) echo "fleet-demo.sh: unknown argument '$1' (expected --backend NAME, --duration SECONDS, --no-cut, --no-build, --python)" >&2; exit 2 ;;
  esac
done
case "$backend" in cyclonedds|fastdds|lcm) ;; *) echo "fleet-demo.sh: --backend $backend: expected cyclonedds, fastdds or lcm" >&2; exit 2 ;; esac
if [ "$(id -u)" != 0 ]; then
  echo "fleet-demo.sh: needs root (it makes hosts out of network, mount and UTS namespaces); scripts/demo.sh runs on one host without it" >&2
  exit 1
fi
if [ "$build" = 1 ]; then
  scripts/install-deps.sh
  cmake --preset default >/dev/null
  targets=(fleet_demo horus_cli)
  if [ "$python" = 1 ]; then targets+=(horus_python); fi
  cmake --build --preset default --target "${targets[@]}"
fi
demo="$PWD/build/default/examples/fleet_demo"
cli="$PWD/build/default/tools/horus"

. scripts/lib/netns-hosts.sh
p="hfd$$"
work="$(mktemp -d /tmp/horus-fleet-demo.XXXXXX)"
cleanup() {
  nh_cleanup
  rm -rf "$work"
}
trap cleanup EXIT
subnet="10.214.$(( $$ % 250 + 1 ))"
nh_create "$p" "$subnet" robot1 robot2 monitor

config="$work/fleet.yaml"
sed "s/^  backend: cyclonedds .*/  backend: $backend/" examples/fleet.yaml >"$config"
on() {  # on HOST command...: runs it in that host's namespaces with the demo's configuration
  local i="$1"
  shift
  nh_on "$i" env HORUS_CONFIG="$config" "$@"
}

echo "horus fleet demo: 3 namespace hosts ($subnet.1-3), fleet topics on $backend, scopes from examples/fleet.yaml"
# The monitor first (DDS discovery is quickest for participants that start after it), then the robots.
if [ "$python" = 1 ]; then
  py=python3
  [ -x /usr/bin/python3 ] && py=/usr/bin/python3  # Debian's, with python3-numpy
  on 3 env PYTHONPATH="$PWD/build/default/python" "$py" "$PWD/examples/python/monitor.py" --robots 2 --duration "$duration" --interval 2 &
else
  on 3 "$demo" --role monitor --robots 2 --duration "$duration" --interval 2 &
fi
monitor=$!
sleep 0.5
nodes=()
for i in 1 2; do
  on "$i" "$demo" --role robot --id "$i" --camera 10 --duration $(( duration + 4 )) >"$work/robot$i.log" 2>&1 &
  nodes+=("$!")
  on "$i" "$demo" --role planner --id "$i" --duration $(( duration + 2 )) >"$work/planner$i.log" 2>&1 &
  nodes+=("$!")
done
if [ "$cut" = 1 ]; then
  # robot2's link: down at a third of the run, up again a third later (the kernel drops the
  # multicast route with the link; the host's network setup puts it back).
  cut_at=$(awk "BEGIN { print $duration / 3 }")
  ( sleep "$cut_at"; nh_link 2 down; echo "--- robot2: link down"
    sleep "$cut_at"; nh_link 2 up; echo "--- robot2: link up" ) &
  nodes+=("$!")
fi
rc=0
wait "$monitor" || rc=$?
echo
echo "host robot1, its planner (camera on host scope, pose on fleet scope):"
tail -n 2 "$work/planner1.log" | sed 's/^/  /'
echo "host robot2, its planner:"
tail -n 2 "$work/planner2.log" | sed 's/^/  /'
echo "host robot1, horus topic list -v (one bridge per fleet topic; the camera never leaves the host):"
on 1 "$cli" topic list -v | sed 's/^/  /'
echo "host monitor, horus topic list (the robots' fleet topics; no camera here):"
on 3 "$cli" topic list | sed 's/^/  /'
echo "host monitor, horus fleet --once:"
on 3 "$cli" fleet --once | sed 's/^/  /'
wait "${nodes[@]}" || true
exit "$rc"
