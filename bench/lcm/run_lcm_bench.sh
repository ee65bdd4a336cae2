#!/usr/bin/env bash
# LCM ping-pong latency and throughput: horus over its LCM backend (HORUS_BACKEND=lcm
# horus-dds-pingpong) against raw LCM (raw-lcm-pingpong: liblcm + lcm-gen C code of the same .lcm
# types, no horus), same channels, same URL, in the same run, on one host (multicast loopback,
# ttl=0) and between two network-namespace hosts joined by a veth pair (ttl=1; root needed).
#
#   bench/lcm/run_lcm_bench.sh [--quick] [--local-only] [--rounds N] [--build-dir DIR] [--tuned-malloc]
#
# HORUS_BENCH_RESULTS=FILE appends every RESULT line (with suite= and setting=) to FILE.
# Each side has its own HORUS_NAMESPACE (its own shared memory, as on two hosts), so horus's
# fleet topic goes publisher -> shared memory -> this host's bridge -> the network -> the other
# host's bridge -> shared memory -> subscriber: the full fleet path against the raw library.
#
# Prints one table per setting: one-way latency (RTT/2) p50 / p99 / p99.9 in microseconds (the
# median over rounds; raw and horus alternate), round trips lost (LCM is best effort: no answer
# within 1 s, 2 s for an image), horus p50 / raw p50; then throughput (messages and MB per
# second a sink receives from a source publishing back to back, and what it lost).
#
# 6 MB images need big UDP receive buffers: the URL asks for recv_buf_size=8 MiB, and as root the
# script raises net.core.rmem_max to 16 MiB while it runs (restored on exit). A program that is
# not built is skipped with a message.
#
# --tuned-malloc runs both implementations with glibc's mmap threshold at 32 MiB (GLIBC_TUNABLES).
# By default a 6 MB malloc is a fresh mmap, page-faulted in on first touch; lcm-gen's C code
# mallocs the whole message on every publish and every decode.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="$here/../../build/default"
quick=0
local_only=0
rounds=3
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --local-only) local_only=1 ;;
    --rounds) rounds="$2"; shift ;;
    --build-dir) build="$2"; shift ;;
    --tuned-malloc) export GLIBC_TUNABLES="glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=268435456" ;;
    *) echo "usage: $0 [--quick] [--local-only] [--rounds N] [--build-dir DIR] [--tuned-malloc]" >&2; exit 2 ;;
  esac
  shift
done
bin="$build/bench"
. "$here/../build_on_demand.sh"
bench_build "$build" horus_dds_pingpong raw_lcm_pingpong
if [ "$quick" = 1 ]; then n_small=2000; warm_small=200; n_image=20; rounds=1; tput_s=1; else n_small=20000; warm_small=500; n_image=200; tput_s=3; fi
warm_image=5
want_rmem=16777216
recv_buf=8388608
# A run-specific port (and group): concurrent runs do not see each other's messages.
port=$(( 20000 + $$ % 30000 ))
group="239.255.76.$(( 100 + $$ % 100 ))"
local_url="udpm://$group:$port?ttl=0&recv_buf_size=$recv_buf"
lan_url="udpm://$group:$port?ttl=1&recv_buf_size=$recv_buf"
unset LCM_DEFAULT_URL

impls=()
if [ -x "$bin/raw-lcm-pingpong" ]; then impls+=("raw-lcm"); else echo "raw-lcm: $bin/raw-lcm-pingpong not built (needs lcm-gen); skipped"; fi
if [ -x "$bin/horus-dds-pingpong" ]; then impls+=("horus-lcm"); else echo "horus-lcm: $bin/horus-dds-pingpong not built; skipped"; fi
[ ${#impls[@]} -gt 0 ] || { echo "no ping-pong programs in $bin (build first)" >&2; exit 1; }

# command for an implementation
prog() {
  case "$1" in
    raw-lcm) echo "$bin/raw-lcm-pingpong" ;;
    horus-lcm) echo "env HORUS_BACKEND=lcm $bin/horus-dds-pingpong" ;;
  esac
}

tmp="$(mktemp -d "${TMPDIR:-/tmp}/lcm_bench.XXXXXX")"
ns1="" ns2="" veth="" old_rmem=""
bg_pid="" bg_hold=""
cleanup() {
  set +e
  stop_bg 0
  [ -n "$ns1" ] && ip netns del "$ns1" 2>/dev/null
  [ -n "$ns2" ] && ip netns del "$ns2" 2>/dev/null
  [ -n "$veth" ] && ip link del "$veth" 2>/dev/null
  if [ -n "$old_rmem" ]; then sysctl -qw net.core.rmem_max="$old_rmem" >/dev/null; fi
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# ---- background receiver (pong / sink): its stdin is a fifo we hold open; closing it = EOF ----
start_bg() {  # out_file command...
  local out="$1"; shift
  local fifo="$tmp/stdin.$RANDOM$RANDOM"
  mkfifo "$fifo"
  "$@" <"$fifo" >"$out" 2>"$out.err" &
  bg_pid=$!
  exec {bg_hold}>"$fifo"
  rm -f "$fifo"
}
# Closes the receiver's stdin, waits up to $1 s for it to exit, then kills it (by its pid).
stop_bg() {
  local grace="${1:-5}" i=0
  if [ -n "$bg_hold" ]; then exec {bg_hold}>&-; bg_hold=""; fi
  [ -n "$bg_pid" ] || return 0
  while kill -0 "$bg_pid" 2>/dev/null && [ "$i" -lt $((grace * 10)) ]; do sleep 0.1; i=$((i + 1)); done
  kill "$bg_pid" 2>/dev/null || true
  wait "$bg_pid" 2>/dev/null || true
  bg_pid=""
}
wait_for() {  # file pattern seconds
  local i=0
  while ! grep -q "$2" "$1" 2>/dev/null && [ "$i" -lt $(($3 * 20)) ]; do
    kill -0 "$bg_pid" 2>/dev/null || break
    sleep 0.05; i=$((i + 1))
  done
  grep -q "$2" "$1" 2>/dev/null
}
why() { head -c 300 "$1" 2>/dev/null | tr '\n' ' '; }

# ---- rmem_max: 6 MB images are ~95 datagrams of 64 KiB each, all in flight at once ----
raise_rmem() {  # [netns]
  local ns="${1:-}" cur
  if [ -n "$ns" ]; then cur=$(ip netns exec "$ns" sysctl -n net.core.rmem_max 2>/dev/null || echo 0)
  else cur=$(sysctl -n net.core.rmem_max 2>/dev/null || echo 0); fi
  [ "$cur" -lt "$want_rmem" ] || return 0
  if [ -z "$ns" ]; then
    if [ "$(id -u)" = 0 ] && sysctl -qw net.core.rmem_max="$want_rmem" >/dev/null 2>&1; then
      old_rmem="$cur"
      echo "net.core.rmem_max raised from $cur to $want_rmem for the run (restored on exit)"
    else
      echo "net.core.rmem_max is $cur (< $want_rmem) and cannot be raised: expect lost images"
    fi
  else
    # Per-namespace only on kernels where the namespace has its own (writable) value.
    ip netns exec "$ns" sysctl -qw net.core.rmem_max="$want_rmem" >/dev/null 2>&1 ||
      echo "net.core.rmem_max in $ns is $cur and cannot be raised there: expect lost images"
  fi
}

make_hosts() {
  ns1="hlcm$$a"; ns2="hlcm$$b"; veth="hl$$a"
  local net="10.$(( 200 + $$ % 50 )).$(( $$ / 50 % 250 ))"
  ip netns add "$ns1" && ip netns add "$ns2" &&
  ip link add "hl$$a" type veth peer name "hl$$b" &&
  ip link set "hl$$a" netns "$ns1" && ip link set "hl$$b" netns "$ns2" && veth="" &&
  ip -n "$ns1" addr add "$net.1/24" dev "hl$$a" && ip -n "$ns2" addr add "$net.2/24" dev "hl$$b" &&
  for ns in "$ns1" "$ns2"; do ip -n "$ns" link set lo up; done &&
  ip -n "$ns1" link set "hl$$a" up && ip -n "$ns2" link set "hl$$b" up &&
  ip -n "$ns1" route add 224.0.0.0/4 dev "hl$$a" && ip -n "$ns2" route add 224.0.0.0/4 dev "hl$$b" &&
  raise_rmem "$ns1" && raise_rmem "$ns2"
}

# in1/in2: command prefixes putting the sender / receiver on their host; url: the LCM URL
setting_env() {
  if [ "$1" = netns ]; then in1="ip netns exec $ns1"; in2="ip netns exec $ns2"; url="$lan_url"
  else in1=""; in2=""; url="$local_url"; fi
}

# one ping-pong: appends its RESULT line (or a FAILED line) to $results
one() {  # setting impl type
  local setting="$1" impl="$2" type="$3" n warm p in1 in2 url out res
  setting_env "$setting"
  p="$(prog "$impl")"
  if [ "$type" = image ]; then n=$n_image; warm=$warm_image; else n=$n_small; warm=$warm_small; fi
  out="$tmp/pong.out"
  # pong: stops at EOF on its stdin, at the stop marker, or after 300 s
  start_bg "$out" $in2 env HORUS_NAMESPACE=bench_b$$ HORUS_LCM_URL="$url" $p pong 0 "$type" 300
  if ! wait_for "$out" ready 10; then
    stop_bg 1
    echo "FAILED impl=$impl type=$type pong: $(why "$out.err") round=$r" >>"$results"
    return
  fi
  res=$($in1 env HORUS_NAMESPACE=bench_a$$ HORUS_LCM_URL="$url" timeout $((60 + n * 3)) $p ping 0 "$type" "$n" "$warm" 2>"$tmp/ping.err" |
        grep RESULT || true)
  stop_bg 5
  if [ -n "$res" ]; then echo "$res round=$r"; else echo "FAILED impl=$impl type=$type ping: $(why "$tmp/ping.err") round=$r"; fi >>"$results"
}

# one throughput run: a sink (second host) counts what a source publishes for $tput_s seconds;
# appends the sink's RESULT line (or FAILED) and the source's SENT line to $results
tput() {  # setting impl type
  local setting="$1" impl="$2" type="$3" p in1 in2 url out sent
  setting_env "$setting"
  p="$(prog "$impl")"
  out="$tmp/sink.out"
  start_bg "$out" $in2 env HORUS_NAMESPACE=bench_b$$ HORUS_LCM_URL="$url" $p sink 0 "$type" $((tput_s + 5))
  if ! wait_for "$out" ready 10; then
    stop_bg 1
    echo "FAILED impl=$impl type=$type mode=tput sink: $(why "$out.err")" >>"$results"
    return
  fi
  sent=$($in1 env HORUS_NAMESPACE=bench_a$$ HORUS_LCM_URL="$url" timeout $((tput_s + 40)) $p source 0 "$type" "$tput_s" 2>/dev/null |
         grep '^SENT' || true)
  # The sink ends at the stop marker; if every marker was lost, at EOF (raw) or after its seconds.
  wait_for "$out" RESULT 2 || { [ -n "$bg_hold" ] && exec {bg_hold}>&- && bg_hold=""; wait_for "$out" RESULT 6; } || true
  stop_bg 2
  if grep -q RESULT "$out"; then
    grep RESULT "$out" >>"$results"
  else
    echo "FAILED impl=$impl type=$type mode=tput sink: $(why "$out.err")" >>"$results"
  fi
  if [ -n "$sent" ]; then echo "$sent" >>"$results"; fi
}

run_setting() {
  local setting="$1" type r impl
  results="$tmp/results.$setting"
  : >"$results"
  for type in cmdvel kilobyte image; do
    for r in $(seq 1 "$rounds"); do
      for impl in "${impls[@]}"; do one "$setting" "$impl" "$type"; done
    done
  done
  for type in cmdvel kilobyte image; do
    for impl in "${impls[@]}"; do tput "$setting" "$impl" "$type"; done
  done
  python3 "$here/lcm_table.py" "$setting" <"$results"
  # scripts/bench.sh collects the raw lines (HORUS_BENCH_RESULTS: a file to append them to).
  if [ -n "${HORUS_BENCH_RESULTS:-}" ]; then
    grep -E '^(RESULT|FAILED)' "$results" | sed "s/^\(RESULT\|FAILED\) /\1 suite=lcm setting=$setting /" >>"$HORUS_BENCH_RESULTS" || true
  fi
}

echo "horus LCM benchmark (one-way = RTT/2), $rounds round(s), $(nproc) CPUs, kernel $(uname -r)"
echo "implementations: ${impls[*]}; URL (one host): $local_url${GLIBC_TUNABLES:+; GLIBC_TUNABLES=$GLIBC_TUNABLES}"
raise_rmem
run_setting local
if [ "$local_only" = 0 ]; then
  if [ "$(id -u)" = 0 ] && make_hosts; then
    echo "two hosts: namespaces $ns1 / $ns2 over a veth pair (MTU 1500), URL $lan_url"
    run_setting netns
  else
    echo "(namespace hosts skipped: needs root and ip netns)"
  fi
fi
