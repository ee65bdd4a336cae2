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

# horus against the raw programs; horus mapped onto ROS 2 (BENCH_ROS2=1) against horus's own mapping.
IMPLS = ["raw-cyclone", "horus-cyclonedds", "horus-cyclonedds-ros2", "raw-fastdds", "horus-fastdds", "horus-fastdds-ros2"]
BASE = {"horus-cyclonedds": "raw-cyclone", "horus-fastdds": "raw-fastdds",
        "horus-cyclonedds-ros2": "horus-cyclonedds", "horus-fastdds-ros2": "horus-fastdds"}
title = "one host (loopback)" if setting == "local" else "two namespace hosts (veth)"
print(f"\n{title}  (/base: horus-<dds> against the raw program of its library; horus-<dds>-ros2, mapped onto ROS 2, against horus-<dds>)")
print(f"{'type':<9} {'implementation':<22} {'p50 us':>9} {'p99 us':>9} {'p99.9 us':>9} {'lost':>5} {'/base p50':>14}")
for t in ["cmdvel", "kilobyte", "image"]:
    med = {}
    for impl in IMPLS:
        rs = rows.get(("lat", t, impl))
        if not rs:
            continue
        p50 = statistics.median(float(r["p50_ns"]) for r in rs) / 1000
        p99 = statistics.median(float(r["p99_ns"]) for r in rs) / 1000
        p999 = statistics.median(float(r["p999_ns"]) for r in rs) / 1000
        lost = sum(int(r.get("lost", 0)) for r in rs)
        med[impl] = p50
        base = BASE.get(impl)
        ratio = f"{p50 / med[base]:.2f}x" if base in med else ""
        print(f"{t:<9} {impl:<22} {p50:>9.1f} {p99:>9.1f} {p999:>9.1f} {lost:>5} {ratio:>14}")
print(f"\n{'type':<9} {'implementation':<22} {'msgs/s':>10} {'MB/s':>9} {'lost':>7} {'/base':>10}   "
      "(throughput, one sink; the raw programs with horus's reliable QoS: KEEP_ALL, the same history "
      "depths; lost: the raw sink's sequence gaps, horus's dropped count)")
for t in ["cmdvel", "kilobyte", "image"]:
    rate = {}
    for impl in IMPLS:
        rs = rows.get(("tput", t, impl))
        if not rs:
            continue
        r = statistics.median(float(x["rate"]) for x in rs)
        mb = statistics.median(float(x["mbps"]) for x in rs)
        lost = sum(int(x.get("lost", x.get("dropped", 0))) for x in rs)
        rate[impl] = r
        base = BASE.get(impl)
        ratio = f"{r / rate[base]:.2f}x" if base in rate and rate[base] > 0 else ""
        print(f"{t:<9} {impl:<22} {r:>10.0f} {mb:>9.1f} {lost:>7} {ratio:>10}")
for f in failed:
    print(f)
