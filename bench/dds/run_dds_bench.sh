#!/usr/bin/env bash
# DDS ping-pong latency: horus over Cyclone DDS and Fast DDS against the raw libraries (programs
# built from idlc / fastddsgen output of the same IDL, no horus), same QoS, same transport
# settings (UDP only, no shared memory), in the same run, on one host (loopback) and between
# two network-namespace hosts joined by a veth pair (root needed for that part).
#
#   bench/dds/run_dds_bench.sh [--quick] [--local-only] [--poll] [--secure] [--rounds N] [--build-dir DIR]
#
# --secure: what DDS-Security costs. A keystore made with `horus security` (identities bench_a
# and bench_b, everything allowed), and every implementation, raw and horus, plain, with every
# topic signed, then encrypted (the governance signed again between them); CmdVel and a 1080p
# Image; security_table.py prints p50 and throughput per protection and their ratio to plain.
#
# Each side has its own HORUS_NAMESPACE (its own shared memory, as on two hosts), so horus's
# fleet topic goes publisher -> shared memory -> this host's bridge -> the network -> the other
# host's bridge -> shared memory -> subscriber: the full fleet path against the raw library.
#
# HORUS_BENCH_RESULTS=FILE appends every RESULT line (with suite= and setting=) to FILE.
# Prints one table per setting: one-way latency (RTT/2) p50 / p99 / p99.9 in microseconds, the
# median over rounds (raw and horus alternate), and horus p50 / raw p50; then throughput
# (messages and MB per second a sink receives from a source sending back to back, reliable).
# Every receiver blocks: the raw programs in a waitset (dds_waitset_wait / WaitSet::wait), horus in
# recv_for. --poll makes every receiver poll instead (BENCH_POLL=1: the raw programs take in a
# loop, horus calls recv() in a loop), yielding between empty polls.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="$here/../../build/default"
quick=0
local_only=0
rounds=3
secure=0
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --local-only) local_only=1 ;;
    --poll) export BENCH_POLL=1 ;;
    --secure) secure=1 ;;
    --rounds) rounds="$2"; shift ;;
    --build-dir) build="$2"; shift ;;
    *) echo "usage: $0 [--quick] [--local-only] [--poll] [--secure] [--rounds N] [--build-dir DIR]" >&2; exit 2 ;;
  esac
  shift
done
bin="$build/bench"
. "$(dirname "$0")/../build_on_demand.sh"
bench_build "$build" horus_dds_pingpong raw_cyclone_pingpong raw_fastdds_pingpong
[ "$secure" = 0 ] || bench_build "$build" horus_cli
domain=$(( 1 + $$ % 200 ))
if [ "$quick" = 1 ]; then n_small=2000; n_image=30; rounds=1; tput_s=1; else n_small=20000; n_image=200; tput_s=3; fi

impls=()
[ -x "$bin/raw-cyclone-pingpong" ] && impls+=("raw-cyclone")
[ -x "$bin/horus-dds-pingpong" ] && impls+=("horus-cyclonedds")
[ -x "$bin/raw-fastdds-pingpong" ] && impls+=("raw-fastdds")
[ -x "$bin/horus-dds-pingpong" ] && impls+=("horus-fastdds")
# The same topics mapped onto ROS 2 (rt/..., the ROS 2 types, converted): against horus's own.
[ -x "$bin/horus-dds-pingpong" ] && [ "$secure" = 0 ] && impls+=("horus-cyclonedds-ros2" "horus-fastdds-ros2")
[ ${#impls[@]} -gt 0 ] || { echo "no ping-pong programs in $bin (build first)" >&2; exit 1; }

# --secure: the keystore, each side's files for the raw programs, and the protection in force.
protection=plain
types="cmdvel image"
ks=""
if [ "$secure" = 1 ]; then
  ks="$(mktemp -d)/keys"
  cli="$build/tools/horus"
  "$cli" security keystore init "$ks" >/dev/null
  for side in a b; do
    "$cli" security host create "$ks" "bench_$side" >/dev/null
    "$cli" security permissions "$ks" "bench_$side" --publish '**' --subscribe '**' >/dev/null
    "$cli" security dds-config "$ks" "bench_$side" --for cyclonedds -o "$ks/hosts/bench_$side/cyclonedds.xml" >/dev/null
    "$cli" security dds-config "$ks" "bench_$side" --for fastdds -o "$ks/hosts/bench_$side/fastdds.xml" >/dev/null
  done
fi
# Every topic signed or encrypted: the governance signed again from a one-rule file.
set_protection() {
  protection="$1"
  [ "$1" = plain ] && return
  printf 'topics:\n  - match: "**"\n    protection: %s\n' "$1" >"$ks/protection.yaml"
  "$build/tools/horus" security governance "$ks" --config "$ks/protection.yaml" >/dev/null
}
# The environment that secures side a or b of an implementation (nothing when plain).
sec_env() {  # impl side
  [ "$protection" = plain ] && return
  local h="$ks/hosts/bench_$2"
  case "$1" in
    horus-*) echo "HORUS_SECURITY=enforce HORUS_SECURITY_KEYSTORE=$ks HORUS_SECURITY_IDENTITY=bench_$2" ;;
    raw-cyclone) echo "CYCLONEDDS_URI=file://$h/cyclonedds.xml" ;;
    raw-fastdds) echo "FASTRTPS_DEFAULT_PROFILES_FILE=$h/fastdds.xml" ;;
  esac
}

# command prefix for an implementation
prog() {
  case "$1" in
    raw-cyclone) echo "$bin/raw-cyclone-pingpong" ;;
    raw-fastdds) echo "$bin/raw-fastdds-pingpong" ;;
    horus-cyclonedds) echo "env HORUS_BACKEND=cyclonedds $bin/horus-dds-pingpong" ;;
    horus-fastdds) echo "env HORUS_BACKEND=fastdds $bin/horus-dds-pingpong" ;;
    horus-cyclonedds-ros2) echo "env HORUS_BACKEND=cyclonedds BENCH_ROS2=1 $bin/horus-dds-pingpong" ;;
    horus-fastdds-ros2) echo "env HORUS_BACKEND=fastdds BENCH_ROS2=1 $bin/horus-dds-pingpong" ;;
  esac
}

ns1="" ns2=""
cleanup() {
  [ -n "$ks" ] && rm -rf "$(dirname "$ks")"
  pkill -f "pingpong pong $domain " 2>/dev/null || true
  [ -n "$ns1" ] && ip netns del "$ns1" 2>/dev/null || true
  [ -n "$ns2" ] && ip netns del "$ns2" 2>/dev/null || true
}
trap cleanup EXIT

make_hosts() {
  ns1="hbench$$a"; ns2="hbench$$b"
  ip netns add "$ns1" && ip netns add "$ns2" &&
  ip link add "hb$$a" type veth peer name "hb$$b" &&
  ip link set "hb$$a" netns "$ns1" && ip link set "hb$$b" netns "$ns2" &&
  ip -n "$ns1" addr add 10.214.0.1/24 dev "hb$$a" && ip -n "$ns2" addr add 10.214.0.2/24 dev "hb$$b" &&
  for ns in "$ns1" "$ns2"; do ip -n "$ns" link set lo up; done &&
  ip -n "$ns1" link set "hb$$a" up && ip -n "$ns2" link set "hb$$b" up &&
  ip -n "$ns1" route add 224.0.0.0/4 dev "hb$$a" && ip -n "$ns2" route add 224.0.0.0/4 dev "hb$$b"
}

# one ping-pong: prints the RESULT line (or a FAILED line)
one() {  # setting impl type
  local setting="$1" impl="$2" type="$3" n warm p
  p="$(prog "$impl")"
  if [ "$type" = image ]; then n=$n_image; warm=10; else n=$n_small; warm=500; fi
  local in1="" in2="" envs="BENCH_LOCALHOST=1"
  if [ "$setting" = netns ]; then in1="ip netns exec $ns1"; in2="ip netns exec $ns2"; envs="BENCH_LOCALHOST=0"; fi
  # pong: stdin held open by a sleep (it stops at EOF, at the stop sample, or after 300 s)
  ( sleep 320 | $in2 env HORUS_NAMESPACE=bench_b$$ $envs $(sec_env "$impl" b) $p pong $domain "$type" 300 >/dev/null 2>&1 & )
  sleep 0.5
  local out
  out=$($in1 env HORUS_NAMESPACE=bench_a$$ $envs $(sec_env "$impl" a) timeout 300 $p ping $domain "$type" $n $warm 2>&1 | grep RESULT || echo "FAILED impl=$impl type=$type")
  pkill -f "pingpong pong $domain $type" 2>/dev/null || true
  sleep 0.3
  echo "$out"
}

# one throughput run: a sink (second host) counts what a source sends for $tput_s seconds. The
# raw programs run with horus's reliable QoS (BENCH_KEEP_ALL=1): KEEP_ALL, a reader holding at
# most 4096 samples, and on Fast DDS a writer holding what horus's does (256 samples, the
# image's 4: backend_dds/src/fastdds_endpoint.cpp); each sink counts the gaps in the sequence
# numbers it received (lost=), as horus's counts its dropped messages.
tput() {  # setting impl type
  local setting="$1" impl="$2" type="$3" p out
  p="$(prog "$impl")"
  case $impl in
    raw-*) local depth=256; [ "$type" = image ] && depth=4
           p="env BENCH_KEEP_ALL=1 BENCH_KEEP_ALL_DEPTH=$depth $p" ;;
  esac
  local in1="" in2="" envs="BENCH_LOCALHOST=1"
  if [ "$setting" = netns ]; then in1="ip netns exec $ns1"; in2="ip netns exec $ns2"; envs="BENCH_LOCALHOST=0"; fi
  out="$(mktemp)"
  ( sleep $((tput_s + 40)) | $in2 env HORUS_NAMESPACE=bench_b$$ $envs $(sec_env "$impl" b) timeout $((tput_s + 40)) $p sink $domain "$type" $((tput_s + 30)) >"$out" 2>&1 & )
  sleep 0.5
  $in1 env HORUS_NAMESPACE=bench_a$$ $envs $(sec_env "$impl" a) timeout $((tput_s + 40)) $p source $domain "$type" "$tput_s" >/dev/null 2>&1 || true
  local deadline=$((SECONDS + 10))
  while ! grep -q RESULT "$out" && [ $SECONDS -lt $deadline ]; do sleep 0.2; done
  grep RESULT "$out" || echo "FAILED impl=$impl type=$type mode=tput"
  pkill -f "pingpong sink $domain $type" 2>/dev/null || true
  rm -f "$out"
  sleep 0.3
}

run_setting() {
  local setting="$1" results=""
  if [ "$secure" = 1 ]; then
    for prot in plain sign encrypt; do
      set_protection "$prot"
      for type in $types; do
        for r in $(seq 1 "$rounds"); do
          for impl in "${impls[@]}"; do results+="$(one "$setting" "$impl" "$type") round=$r protection=$prot"$'\n'; done
        done
        for impl in "${impls[@]}"; do results+="$(tput "$setting" "$impl" "$type") protection=$prot"$'\n'; done
      done
    done
    echo "$results" | python3 "$here/security_table.py" "$setting"
    if [ -n "${HORUS_BENCH_RESULTS:-}" ]; then
      grep -E '^(RESULT|FAILED)' <<<"$results" | sed "s/^\(RESULT\|FAILED\) /\1 suite=dds-security setting=$setting /" >>"$HORUS_BENCH_RESULTS" || true
    fi
    return
  fi
  for type in cmdvel kilobyte image; do
    for r in $(seq 1 "$rounds"); do
      for impl in "${impls[@]}"; do
        results+="$(one "$setting" "$impl" "$type") round=$r"$'\n'
      done
    done
  done
  for type in cmdvel kilobyte image; do
    for impl in "${impls[@]}"; do
      results+="$(tput "$setting" "$impl" "$type")"$'\n'
    done
  done
  echo "$results" | python3 "$here/dds_table.py" "$setting"
  # scripts/bench.sh collects the raw lines (HORUS_BENCH_RESULTS: a file to append them to).
  if [ -n "${HORUS_BENCH_RESULTS:-}" ]; then
    grep -E '^(RESULT|FAILED)' <<<"$results" | sed "s/^\(RESULT\|FAILED\) /\1 suite=dds setting=$setting /" >>"$HORUS_BENCH_RESULTS" || true
  fi
}

echo "horus DDS latency (one-way = RTT/2), $rounds round(s), domain $domain, $(nproc) CPUs$([ "$secure" = 1 ] && echo ", DDS-Security: plain, signed, encrypted")"
run_setting local
if [ "$local_only" = 0 ]; then
  if [ "$(id -u)" = 0 ] && make_hosts; then
    run_setting netns
  else
    echo "(namespace hosts skipped: needs root and ip netns)"
  fi
fi
