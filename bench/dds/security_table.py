"""Reads RESULT lines of run_dds_bench.sh --secure on stdin (each with protection=plain|sign|encrypt)
and prints what DDS-Security costs: per message type and implementation, the one-way p50 (median
over rounds) and the throughput plain, signed and encrypted, with each one's ratio to plain, and
horus against the raw library under the same protection; then each cell's p50 / p99 / p99.9 (median
over rounds) with the spread of p50 over the rounds (min-max)."""
import statistics
import sys

setting = sys.argv[1]
lat, tput, failed = {}, {}, []
for line in sys.stdin:
    line = line.strip()
    if line.startswith("FAILED"):
        failed.append(line)
        continue
    if not line.startswith("RESULT"):
        continue
    kv = dict(p.split("=", 1) for p in line.split()[1:])
    key = (kv["type"], kv["impl"], kv.get("protection", "plain"))
    (tput if kv.get("mode") == "tput" else lat).setdefault(key, []).append(kv)

impls = ["raw-cyclone", "horus-cyclonedds", "raw-fastdds", "horus-fastdds"]
base = {"horus-cyclonedds": "raw-cyclone", "horus-fastdds": "raw-fastdds"}
prots = ["plain", "sign", "encrypt"]
title = "one host (loopback)" if setting == "local" else "two namespace hosts (veth)"
print(f"\n{title}: one-way p50 in us (ratio to plain); horus/raw p50 under encryption")
print(f"{'type':<7} {'implementation':<17} {'plain':>8} {'signed':>16} {'encrypted':>16} {'horus/raw':>10}")
p50 = {}
for (t, impl, prot), rs in lat.items():
    p50[(t, impl, prot)] = statistics.median(float(r["p50_ns"]) for r in rs) / 1000
for t in ["cmdvel", "image"]:
    for impl in impls:
        if (t, impl, "plain") not in p50:
            continue
        plain = p50[(t, impl, "plain")]
        cells = [f"{plain:>8.1f}"]
        for prot in ["sign", "encrypt"]:
            v = p50.get((t, impl, prot))
            cells.append(f"{v:>8.1f} ({v / plain:.2f}x)" if v else f"{'-':>16}")
        b = base.get(impl)
        enc, benc = p50.get((t, impl, "encrypt")), p50.get((t, b, "encrypt")) if b else None
        cells.append(f"{enc / benc:>9.2f}x" if enc and benc else f"{'':>10}")
        print(f"{t:<7} {impl:<17} " + " ".join(cells))
print(f"\n{title}: throughput in messages/s and MB/s (ratio to plain), one sink")
print(f"{'type':<7} {'implementation':<17} {'plain':>18} {'signed':>26} {'encrypted':>26}")
for t in ["cmdvel", "image"]:
    for impl in impls:
        rs = tput.get((t, impl, "plain"))
        if not rs:
            continue
        def med(prot):
            x = tput.get((t, impl, prot))
            if not x:
                return None
            return statistics.median(float(r["rate"]) for r in x), statistics.median(float(r["mbps"]) for r in x)
        plain = med("plain")
        cells = [f"{plain[0]:>8.0f} {plain[1]:>7.1f} MB"]
        for prot in ["sign", "encrypt"]:
            v = med(prot)
            ratio = f"({v[0] / plain[0]:.2f}x)" if v and plain[0] > 0 else ""
            cells.append(f"{v[0]:>8.0f} {v[1]:>7.1f} MB {ratio:>7}" if v else f"{'-':>26}")
        print(f"{t:<7} {impl:<17} " + " ".join(cells))
print(f"\n{title}: one-way p50 [min-max over rounds] / p99 / p99.9 in us, median over rounds")
print(f"{'type':<7} {'implementation':<17} {'protection':<8} {'p50':>9} {'[min-max]':>21} {'p99':>9} {'p99.9':>9}")
for t in ["cmdvel", "image"]:
    for impl in impls:
        for prot in prots:
            rs = lat.get((t, impl, prot))
            if not rs:
                continue
            p50s = [float(r["p50_ns"]) / 1000 for r in rs]
            med = lambda k: statistics.median(float(r[k]) for r in rs) / 1000
            spread = f"[{min(p50s):.1f}-{max(p50s):.1f}]"
            print(f"{t:<7} {impl:<17} {prot:<8} {statistics.median(p50s):>9.1f} {spread:>21} {med('p99_ns'):>9.1f} "
                  f"{med('p999_ns'):>9.1f}")
for f in failed:
    print(f)
