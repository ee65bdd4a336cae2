# Hosts made of namespaces, for scripts that run as root (sourced: scripts/fleet-demo.sh,
# bench/fleet/run_fleet_bench.sh). Each host has its own network namespace on a private bridge
# (nothing leaves this machine), its own /dev/shm (a private tmpfs) and hostname (UTS), held by
# a `sleep` that every process of the host joins with nsenter.
#
#   nh_create PREFIX SUBNET NAME...   hosts 1..N named NAME... (10.x.y.1-N on SUBNET.0/24)
#   nh_on I CMD...                    runs CMD on host I (1-based)
#   nh_link I down|up                 host I's link (up restores the multicast route)
#   nh_cleanup                        kills the holders, deletes the namespaces
nh_prefix=""
nh_count=0
nh_holders=()

nh_create() {
  nh_prefix="$1"
  local subnet="$2"
  shift 2
  local i=0 name ns
  ip netns add "${nh_prefix}b"
  ip -n "${nh_prefix}b" link add br0 type bridge mcast_snooping 0
  ip -n "${nh_prefix}b" link set br0 up
  for name in "$@"; do
    i=$((i + 1))
    ns="${nh_prefix}h$i"
    ip netns add "$ns"
    ip link add "${nh_prefix}v$i" type veth peer name "${nh_prefix}p$i"
    ip link set "${nh_prefix}v$i" netns "$ns"
    ip link set "${nh_prefix}p$i" netns "${nh_prefix}b"
    ip -n "$ns" link set "${nh_prefix}v$i" name eth0
    ip -n "$ns" addr add "$subnet.$i/24" dev eth0
    ip -n "$ns" link set eth0 up
    ip -n "$ns" link set lo up
    ip -n "$ns" route add 224.0.0.0/4 dev eth0
    ip -n "${nh_prefix}b" link set "${nh_prefix}p$i" master br0
    ip -n "${nh_prefix}b" link set "${nh_prefix}p$i" up
    ip netns exec "$ns" unshare --mount --uts --propagation private \
      sh -c "mount -t tmpfs -o mode=1777 tmpfs /dev/shm && hostname $name && exec sleep infinity" &
    nh_holders+=("$!")
  done
  nh_count=$i
  local h
  for h in "${nh_holders[@]}"; do
    for _ in $(seq 200); do [ "$(cat /proc/$h/comm 2>/dev/null)" = sleep ] && break; sleep 0.05; done
  done
}

nh_on() {
  local h="${nh_holders[$(( $1 - 1 ))]}"
  shift
  nsenter -t "$h" -n -m -u -- "$@"
}

nh_link() {
  ip -n "${nh_prefix}h$1" link set eth0 "$2"
  if [ "$2" = up ]; then ip -n "${nh_prefix}h$1" route replace 224.0.0.0/4 dev eth0; fi
}

nh_cleanup() {
  local h i
  for h in "${nh_holders[@]}"; do kill -9 "$h" 2>/dev/null || true; done
  for h in "${nh_holders[@]}"; do wait "$h" 2>/dev/null || true; done
  for i in $(seq "$nh_count"); do ip netns del "${nh_prefix}h$i" 2>/dev/null || true; done
  if [ -n "$nh_prefix" ]; then ip netns del "${nh_prefix}b" 2>/dev/null || true; fi
  nh_holders=()
  nh_count=0
}
