"""Reads RESULT lines of the DDS ping-pongs on stdin and prints the table of run_dds_bench.sh."""
import statistics
import sys

setting = sys.argv[1]
rows = {}
failed = []
for line in sys.stdin:
    line = line.strip()
    if line.startswith("FAILED"):
        failed.append(line)
        continue
    if not line.startswith("RESULT"):
        continue
    kv = dict(p.split("=", 1) for p in line.split()[1:])
    key = "tput" if kv.get("mode") == "tput" else "lat"
    rows.setdefault((key, kv["type"], kv["impl"]), []).append(kv)

title = "one host (loopback)" if setting == "local" else "two namespace hosts (veth)"
print(f"\n{title}")
print(f"{'type':<9} {'implementation':<17} {'p50 us':>9} {'p99 us':>9} {'p99.9 us':>9} {'lost':>5} {'horus/raw p50':>14}")
for t in ["cmdvel", "kilobyte", "image"]:
    med = {}
    for impl in ["raw-cyclone", "horus-cyclonedds", "raw-fastdds", "horus-fastdds"]:
        rs = rows.get(("lat", t, impl))
        if not rs:
            continue
        p50 = statistics.median(float(r["p50_ns"]) for r in rs) / 1000
        p99 = statistics.median(float(r["p99_ns"]) for r in rs) / 1000
        p999 = statistics.median(float(r["p999_ns"]) for r in rs) / 1000
        lost = sum(int(r.get("lost", 0)) for r in rs)
        med[impl] = p50
        base = {"horus-cyclonedds": "raw-cyclone", "horus-fastdds": "raw-fastdds"}.get(impl)
        ratio = f"{p50 / med[base]:.2f}x" if base in med else ""
        print(f"{t:<9} {impl:<17} {p50:>9.1f} {p99:>9.1f} {p999:>9.1f} {lost:>5} {ratio:>14}")
print(f"\n{'type':<9} {'implementation':<17} {'msgs/s':>10} {'MB/s':>9} {'horus/raw':>10}   (throughput, one sink)")
for t in ["cmdvel", "kilobyte", "image"]:
    rate = {}
    for impl in ["raw-cyclone", "horus-cyclonedds", "raw-fastdds", "horus-fastdds"]:
        rs = rows.get(("tput", t, impl))
        if not rs:
            continue
        r = statistics.median(float(x["rate"]) for x in rs)
        mb = statistics.median(float(x["mbps"]) for x in rs)
        rate[impl] = r
        base = {"horus-cyclonedds": "raw-cyclone", "horus-fastdds": "raw-fastdds"}.get(impl)
        ratio = f"{r / rate[base]:.2f}x" if base in rate and rate[base] > 0 else ""
        print(f"{t:<9} {impl:<17} {r:>10.0f} {mb:>9.1f} {ratio:>10}")
for f in failed:
    print(f)
