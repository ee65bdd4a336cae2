#!/usr/bin/env python3
"""What Python adds to horus, measured against the C++ pair in the same run.

  1. send + recv of a CmdVel on one thread: Python (horus.Topic) and C++ (horus::Topic);
  2. round trips through shared memory between two processes, spinning on both sides:
     Python ping <-> C++ pong, and C++ ping <-> the same C++ pong, for a CmdVel and for
     images of 64x64 and 1920x1080 RGB (the ping loans a slot, sets the stamp and sends it;
     the pong answers with a loan of its own: no byte is copied on either side).

Every figure is p50 / p99 / p99.9 in microseconds, per round, over several rounds (the machine
is shared: the spread is printed). The ping side runs on CPU 0, the pong on the last CPU. Run: bench/python/run.sh (it builds what it needs).

  bench_python.py --peer build/default/bench/horus-py-peer [--rounds 5] [--count 20000] [--quick]
"""

import argparse
import os
import subprocess
import sys
import time

import numpy as np

import horus


def pct(samples_ns):
    a = np.sort(np.asarray(samples_ns, dtype=np.float64)) / 1000.0
    at = lambda q: a[min(len(a) - 1, int(q * len(a)))]
    return at(0.5), at(0.99), at(0.999)


def parse(line):
    p50, p99, p999, _ = (float(x) / 1000.0 for x in line.split())
    return p50, p99, p999


def py_local(count):
    pub = horus.Topic("bench.py.local.py", horus.msg.CmdVel)
    sub = horus.Topic("bench.py.local.py", horus.msg.CmdVel)
    m = horus.msg.CmdVel(linear=1.0, angular=0.5)
    now = time.perf_counter_ns
    out = []
    for _ in range(count):
        t0 = now()
        pub.send(m)
        sub.recv()
        out.append(now() - t0)
    return pct(out)


class Pong:
    def __init__(self, peer, prefix, kind):
        self.proc = subprocess.Popen([peer, "pong", prefix, kind, "600"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True)
        if self.proc.stdout.readline().strip() != "ready":
            raise RuntimeError("horus-py-peer pong did not start")

    def close(self):
        self.proc.stdin.close()
        self.proc.wait(timeout=10)


def py_ping(prefix, kind, count, h=1080, w=1920):
    cls = horus.msg.Image if kind == "image" else horus.msg.CmdVel
    out = horus.Topic(prefix + ".ping", cls)
    back = horus.Topic(prefix + ".pong", cls)
    now = time.perf_counter_ns
    samples = []
    msg = horus.msg.CmdVel(linear=1.0, angular=0.5)
    warmup = count // 10
    for i in range(count + warmup):
        seq = i + 1
        t0 = now()
        if kind == "image":
            loan = out.loan(h, w)
            loan.message.timestamp_ns = seq
            out.send(loan)
        else:
            msg.stamp_nanos = seq
            out.send(msg)
        while True:
            r = back.recv()
            if r is not None and (r.timestamp_ns if kind == "image" else r.stamp_nanos) == seq:
                break
            if now() - t0 > 2_000_000_000:
                raise RuntimeError(f"no pong for ping {i} in 2 s")
        if i >= warmup:
            samples.append(now() - t0)
    return pct(samples)


def cpp(peer, *args):
    out = subprocess.run([peer, *args], capture_output=True, text=True, timeout=600)
    if out.returncode != 0:
        raise RuntimeError(f"horus-py-peer {' '.join(args)}: {out.stderr.strip()}")
    return parse(out.stdout)


def row(name, py, cc):
    return (f"{name:<34} {py[0]:8.2f} {py[1]:8.2f} {py[2]:8.2f}   {cc[0]:8.2f} {cc[1]:8.2f} {cc[2]:8.2f}"
            f"   {py[0] - cc[0]:+8.2f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--peer", required=True, help="horus-py-peer (build/default/bench/horus-py-peer)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--count", type=int, default=20000, help="CmdVel samples per round (images: a tenth)")
    ap.add_argument("--quick", action="store_true", help="one short round (a smoke run)")
    args = ap.parse_args()
    if args.quick:
        args.rounds, args.count = 1, 2000
    os.sched_setaffinity(0, {0})  # as horus-py-peer's ping and local; its pong takes the last CPU
    prefix = f"bench.py.{os.getpid()}"
    cases = [("cmdvel", "CmdVel", None), ("image", "Image 64x64 RGB (12 KiB)", (64, 64)),
             ("image", "Image 1920x1080 RGB (6 MiB)", (1080, 1920))]
    print(f"horus Python benchmark: {args.rounds} rounds; microseconds; Python | C++ measured in the same round")
    print(f"{'':<34} {'Python':>26}   {'C++':>26}   {'p50':>8}")
    print(f"{'':<34} {'p50':>8} {'p99':>8} {'p99.9':>8}   {'p50':>8} {'p99':>8} {'p99.9':>8}   {'added':>8}")
    results = {}
    for r in range(args.rounds):
        print(f"round {r + 1}")
        py, cc = py_local(args.count), cpp(args.peer, "local", str(args.count))
        print(row("send+recv, one thread: CmdVel", py, cc), flush=True)
        results.setdefault("local", []).append((py, cc))
        for kind, name, size in cases:
            n = args.count if size is None else max(200, args.count // 10)
            p = f"{prefix}.{kind}{size[1] if size else ''}"
            pong = Pong(args.peer, p, kind)
            try:
                extra = [str(size[0]), str(size[1])] if size else []
                py = py_ping(p, kind, n, *(size or ()))
                cc = cpp(args.peer, "ping", p, kind, str(n), *extra)
            finally:
                pong.close()
            print(row(f"round trip, 2 processes: {name}", py, cc), flush=True)
            results.setdefault(name, []).append((py, cc))
    if args.rounds > 1:
        print("\nspread over the rounds (p50 min-max, microseconds):")
        for name, rounds in results.items():
            pys = [x[0][0] for x in rounds]
            ccs = [x[1][0] for x in rounds]
            adds = [x[0][0] - x[1][0] for x in rounds]
            print(f"  {name:<32} Python {min(pys):7.2f}-{max(pys):7.2f}   C++ {min(ccs):7.2f}-{max(ccs):7.2f}"
                  f"   added {min(adds):+7.2f} to {max(adds):+7.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
