"""Reads the RESULT / SENT / FAILED lines of the LCM ping-pongs on stdin; prints run_lcm_bench.sh's table.

Latency: the median over rounds of p50 / p99 / p99.9 (one-way = RTT/2, microseconds), the round trips
lost in all rounds, and horus p50 / raw p50. Throughput: messages and MB per second the sink received,
messages lost (raw-lcm's sink counts them from sequence gaps; for horus, "d:N" is the sink topic's
dropped_count(): ring overwrites plus datagrams the kernel dropped), what the source published per
second, and horus / raw msgs/s.
"""
import statistics
import sys

IMPLS = ["raw-lcm", "horus-lcm"]
BASE = {"horus-lcm": "raw-lcm"}
TYPES = ["cmdvel", "kilobyte", "image"]

setting = sys.argv[1] if len(sys.argv) > 1 else "local"
rows = {}
sent = {}
failed = []
for line in sys.stdin:
    line = line.strip()
    if line.startswith("FAILED"):
        failed.append(line)
        continue
    if not (line.startswith("RESULT") or line.startswith("SENT")):
        continue
    kv = dict(p.split("=", 1) for p in line.split()[1:] if "=" in p)
    if "type" not in kv or "impl" not in kv:
        continue
    if line.startswith("SENT"):
        sent.setdefault((kv["type"], kv["impl"]), []).append(kv)
        continue
    key = "tput" if kv.get("mode") == "tput" else "lat"
    rows.setdefault((key, kv["type"], kv["impl"]), []).append(kv)


def med(rs, field, scale=1.0):
    vals = [float(r[field]) for r in rs if field in r]
    return statistics.median(vals) / scale if vals else float("nan")


title = "one host (multicast loopback, ttl=0)" if setting == "local" else "two namespace hosts (veth, ttl=1)"
print(f"\n{title}")
print(f"{'type':<9} {'implementation':<15} {'p50 us':>9} {'p99 us':>9} {'p99.9 us':>9} {'lost':>6} {'horus/raw p50':>14}")
for t in TYPES:
    p50s = {}
    for impl in IMPLS:
        rs = rows.get(("lat", t, impl))
        if not rs:
            continue
        ok = [r for r in rs if "p50_ns" in r]
        lost = sum(int(r.get("lost", 0)) for r in rs)
        if not ok:
            print(f"{t:<9} {impl:<15} {'-':>9} {'-':>9} {'-':>9} {lost:>6}")
            continue
        p50 = med(ok, "p50_ns", 1000)
        p50s[impl] = p50
        base = BASE.get(impl)
        ratio = f"{p50 / p50s[base]:.2f}x" if base in p50s and p50s[base] > 0 else ""
        print(f"{t:<9} {impl:<15} {p50:>9.1f} {med(ok, 'p99_ns', 1000):>9.1f} {med(ok, 'p999_ns', 1000):>9.1f} "
              f"{lost:>6} {ratio:>14}")

print(f"\n{'type':<9} {'implementation':<15} {'msgs/s':>10} {'MB/s':>9} {'lost':>8} {'sent/s':>10} {'horus/raw':>10}"
      "   (throughput, one sink)")
for t in TYPES:
    rates = {}
    for impl in IMPLS:
        rs = rows.get(("tput", t, impl))
        if not rs:
            continue
        rate = med(rs, "rate")
        rates[impl] = rate
        lost = str(sum(int(r["lost"]) for r in rs if "lost" in r)) if any("lost" in r for r in rs) else "-"
        if any("dropped" in r for r in rs):
            lost = "d:" + str(sum(int(r["dropped"]) for r in rs if "dropped" in r))
        ss = sent.get((t, impl))
        sent_rate = f"{med(ss, 'rate'):.0f}" if ss else "-"
        base = BASE.get(impl)
        ratio = f"{rate / rates[base]:.2f}x" if base in rates and rates[base] > 0 else ""
        print(f"{t:<9} {impl:<15} {rate:>10.0f} {med(rs, 'mbps'):>9.1f} {lost:>8} {sent_rate:>10} {ratio:>10}")
for f in failed:
    print(f)
