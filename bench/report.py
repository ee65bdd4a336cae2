"""The report of scripts/bench.sh: reads the results of every round in a folder, prints the
tables (median and min-max over rounds), writes summary.json and summary.md, and draws the plots
(PNG, with python3-matplotlib when it is installed).

    python3 bench/report.py bench/results

Inputs (each optional): local.<round>.json (horus-latency-local --json), shm.<round>.json
(horus-latency-shm --json), fanout.json (horus-fanout --json), hybrid.txt (bench/fleet/hybrid.sh
--results), net_wakeups.txt (bench/net_wakeups.sh),
network.txt (RESULT lines of
bench/dds/run_dds_bench.sh and bench/lcm/run_lcm_bench.sh with HORUS_BENCH_RESULTS).
"""
import glob
import json
import os
import statistics
import sys

out_dir = sys.argv[1] if len(sys.argv) > 1 else "bench/results"
summary = {}
md = []


def spread(values, digits=1):
    """'median (min-max)' of a list of numbers."""
    values = [v for v in values if v is not None]
    if not values:
        return "-"
    med = statistics.median(values)
    if len(values) == 1:
        return f"{med:.{digits}f}"
    return f"{med:.{digits}f} ({min(values):.{digits}f}-{max(values):.{digits}f})"


def stats(values):
    values = [v for v in values if v is not None]
    if not values:
        return None
    return {"median": statistics.median(values), "min": min(values), "max": max(values), "rounds": len(values)}


def table(title, header, rows):
    """Prints a table and keeps it for summary.md."""
    print(f"\n{title}")
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)] if rows else [len(h) for h in header]
    print("  ".join(str(h).ljust(w) for h, w in zip(header, widths)))
    for r in rows:
        print("  ".join(str(c).ljust(w) for c, w in zip(r, widths)))
    md.append(f"\n**{title}**\n")
    md.append("| " + " | ".join(header) + " |")
    md.append("|" + "---|" * len(header))
    for r in rows:
        md.append("| " + " | ".join(str(c) for c in r) + " |")


# The hypervisor places the two vCPUs on one physical core or on two, and moves them between
# runs: the floor is then 25-45 ns or 100-250 ns, and a ratio to it means different things.
# Rounds are grouped by where their true floor says the CPUs were.
SHARED_CORE_FLOOR_NS = 80.0


def placement(key, rounds, third_label):
    """rounds: per round (one-line floor p50, two-line floor p50, horus CmdVel p50, a third
    figure). The placement is read from the better floor; horus is shown against both floors,
    per placement and in every round (the two-line floor is the cost of the message's own two
    lines, the target's reference: horus <= 1.1x it)."""
    groups = {"separate cores": [], "one shared core": []}
    for one, two, horus, third in rounds:
        groups["one shared core" if min(one, two) < SHARED_CORE_FLOOR_NS else "separate cores"].append((one, two, horus, third))
    rows = []
    summary.setdefault("placement", {})[key] = {}
    for name, g in groups.items():
        if not g:
            continue
        r1 = [h / o for o, _, h, _ in g if o]
        r2 = [h / t for _, t, h, _ in g if t]
        rows.append([name, len(g), spread([x[0] for x in g]), spread([x[1] for x in g]), spread([x[2] for x in g]),
                     spread(r1, 2) + "x", spread(r2, 2) + "x", spread([x[3] for x in g], 2)])
        summary["placement"][key][name] = {"rounds": len(g), "floor_one_line_p50_ns": stats([x[0] for x in g]),
                                           "floor_two_lines_p50_ns": stats([x[1] for x in g]),
                                           "horus_p50_ns": stats([x[2] for x in g]),
                                           "over_one_line": stats(r1), "over_two_lines": stats(r2),
                                           "third": stats([x[3] for x in g])}
    table(f"{key}: rounds by where the two CPUs were (better floor < {SHARED_CORE_FLOOR_NS:.0f} ns: one core), "
          "horus CmdVel p50 against both floors",
          ["placement", "rounds", "one-line floor ns", "two-line floor ns", "horus ns", "horus / one-line",
           "horus / two-line (target <= 1.1)", third_label], rows)
    per_round = [[i + 1, "one shared core" if min(o, t) < SHARED_CORE_FLOOR_NS else "separate cores", f"{o:.1f}",
                  f"{t:.1f}", f"{h:.1f}", f"{h / o:.2f}x" if o else "-", f"{h / t:.2f}x" if t else "-"]
                 for i, (o, t, h, _) in enumerate(rounds)]
    table(f"{key}: every round", ["round", "placement", "one-line floor ns", "two-line floor ns", "horus ns",
                                  "horus / one-line", "horus / two-line"], per_round)


def load_rounds(prefix):
    files = sorted(glob.glob(os.path.join(out_dir, f"{prefix}.*.json")))
    rounds = []
    for f in files:
        try:
            with open(f) as fh:
                rounds.append(json.load(fh))
        except (OSError, ValueError) as e:
            print(f"report: skipping {f}: {e}", file=sys.stderr)
    return rounds


# -- the local path (threads) ---------------------------------------------------------------
local = load_rounds("local")
if local:
    def by_name(rnd):
        return {r["name"]: r for r in rnd}
    names = [r["name"] for r in local[0]]
    rows = []
    summary["local"] = {}
    for name in names:
        rs = [by_name(rnd).get(name) for rnd in local]
        rs = [r for r in rs if r]
        sec = rs[0]["section"]
        if sec == "cross_thread_one_way":
            cells = [spread([r["p50_ns"] for r in rs]), spread([r["p99_ns"] for r in rs]),
                     spread([r["p999_ns"] for r in rs]), spread([r["ratio"] for r in rs], 2) + "x floor"]
            summary["local"][name] = {"p50_ns": stats([r["p50_ns"] for r in rs]),
                                      "p99_ns": stats([r["p99_ns"] for r in rs]),
                                      "ratio_to_floor": stats([r["ratio"] for r in rs])}
        elif sec == "throughput":
            cells = [spread([r["value"] / 1e6 for r in rs]) + " M msg/s", "", "", spread([r["ratio"] for r in rs], 2) + "x boost"]
            summary["local"][name] = {"msgs_per_s": stats([r["value"] for r in rs]), "ratio_to_boost": stats([r["ratio"] for r in rs])}
        else:
            cells = [spread([r["value"] for r in rs], 2) + " ns/op", "", "", spread([r["ratio"] for r in rs], 2) + "x boost"]
            summary["local"][name] = {"ns_per_op": stats([r["value"] for r in rs]), "ratio_to_boost": stats([r["ratio"] for r in rs])}
        rows.append([name] + cells)
    table(f"local path, CmdVel (horus-latency-local), {len(local)} rounds: median (min-max)",
          ["measurement", "p50 / value", "p99", "p99.9", "ratio (median of rounds)"], rows)
    placement("local", [(by_name(r)["floor: one line"]["p50_ns"], by_name(r)["floor: two lines 256 B apart"]["p50_ns"],
                         by_name(r)["horus Topic<CmdVel>"]["p50_ns"], by_name(r)["horus Topic try_send/recv"]["ratio"])
                        for r in local], "horus / boost throughput")

# -- between processes (shared memory) --------------------------------------------------------
shm = load_rounds("shm")
if shm:
    labels = [("floor_one_line", "floor: one line"), ("floor_two_lines", "floor: two lines 256 B apart"),
              ("cmdvel", "horus Topic<CmdVel> (16 B)"), ("kib", "horus 1 KiB"),
              ("image", "horus Image 1080p, loan"), ("image_copy", "horus Image 1080p, send() copy"),
              ("iceoryx_16b", "iceoryx 2.0, 16 B"), ("iceoryx_1kib", "iceoryx 2.0, 1 KiB"),
              ("iceoryx_image", "iceoryx 2.0, 6 MB chunk")]
    rows = []
    summary["shm"] = {}
    for key, label in labels:
        rs = [rnd[key] for rnd in shm if key in rnd]
        if not rs:
            continue
        ratio = spread([r.get("ratio") for r in rs], 2)
        rows.append([label, spread([r["p50"] for r in rs]), spread([r["p99"] for r in rs]),
                     spread([r["p999"] for r in rs]), ratio + ("x floor" if ratio != "-" else "")])
        summary["shm"][key] = {"p50_ns": stats([r["p50"] for r in rs]), "p99_ns": stats([r["p99"] for r in rs]),
                               "ratio_to_floor": stats([r.get("ratio") for r in rs])}
    tput = [rnd.get("throughput_msgs_per_s", 0) / 1e6 for rnd in shm]
    rows.append(["lossless throughput, CmdVel", spread(tput) + " M msg/s", "", "", ""])
    summary["shm"]["throughput_msgs_per_s"] = stats([t * 1e6 for t in tput])
    vs = [rnd["vs_iceoryx"] for rnd in shm if "vs_iceoryx" in rnd]
    if vs:
        rows.append(["iceoryx p50 / horus p50", "CmdVel " + spread([v["cmdvel"] for v in vs]) + "x",
                     "1 KiB " + spread([v["kib"] for v in vs]) + "x", "image " + spread([v["image"] for v in vs]) + "x", ""])
        summary["shm"]["vs_iceoryx"] = {k: stats([v[k] for v in vs]) for k in ("cmdvel", "kib", "image")}
    table(f"between processes, shared memory (horus-latency-shm), {len(shm)} rounds: ns, median (min-max)",
          ["one-way (RTT/2)", "p50", "p99", "p99.9", "p50 / true floor"], rows)
    placement("shm", [(r["floor_one_line"]["p50"], r["floor_two_lines"]["p50"], r["cmdvel"]["p50"],
                       r.get("throughput_msgs_per_s", 0) / 1e6) for r in shm], "throughput M msg/s")

# -- fan-out and scale -------------------------------------------------------------------------
fanout = None
try:
    with open(os.path.join(out_dir, "fanout.json")) as fh:
        fanout = json.load(fh)
except (OSError, ValueError):
    pass
if fanout:
    summary["fanout"] = fanout
    rows = []
    for r in fanout.get("fanout_latency", []):
        rows.append([r["subscribers"], "horus", spread(r["p50_ns"], 0), spread(r["p99_ns"], 0),
                     spread(r["all_p50_ns"], 0), spread(r["all_p99_ns"], 0), r["missing"], ""])
        if "futex_p50_ns" in r:
            rows.append([r["subscribers"], "raw futex", spread(r["futex_p50_ns"], 0), spread(r["futex_p99_ns"], 0),
                         spread(r["futex_all_p50_ns"], 0), spread(r["futex_all_p99_ns"], 0), r["futex_missing"],
                         "horus / futex " + spread(r["all_p50_over_futex"], 2) + "x"])
        if "iox_p50_ns" in r:
            rows.append([r["subscribers"], "iceoryx 2.0", spread(r["iox_p50_ns"], 0), spread(r["iox_p99_ns"], 0),
                         spread(r["iox_all_p50_ns"], 0), spread(r["iox_all_p99_ns"], 0), r["iox_missing"],
                         "iceoryx / horus " + spread(r["iox_all_p50_over_horus"], 2) + "x"])
    table("fan-out, 1 publisher -> N processes blocked in recv_for (horus-fanout), beside the machine's floor "
          "(N processes in FUTEX_WAIT on one word, one FUTEX_WAKE) and iceoryx 2.0 (WaitSet): ns, median (min-max)",
          ["N", "", "p50", "p99", "all delivered p50", "all delivered p99", "not received",
           "all delivered p50 ratio"], rows)
    rows = [[r["subscribers"], spread(r["msgs_per_s_millions"], 2)] for r in fanout.get("fanout_throughput", [])]
    table("fan-out throughput, lossless (send_blocking)", ["N", "M msg/s to every subscriber"], rows)
    rows = [[r["topics"], spread(r["p50_ns"]), spread(r["p99_ns"])] for r in fanout.get("many_topics", [])]
    table("topics open in both processes, ping-pong on one", ["topics", "p50 ns", "p99 ns"], rows)
    rows = [[r["message"], r["segment_bytes"], r["allocated_bytes"], f'{r["rss_per_topic_kib"]:.1f}']
            for r in fanout.get("memory", [])]
    table("memory of a topic", ["message", "segment bytes (virtual)", "allocated bytes", "RSS KiB per topic"], rows)

# -- the network (DDS, LCM) --------------------------------------------------------------------
net = []
try:
    with open(os.path.join(out_dir, "network.txt")) as fh:
        for line in fh:
            parts = line.split()
            if not parts or parts[0] not in ("RESULT", "FAILED"):
                continue
            kv = dict(p.split("=", 1) for p in parts[1:] if "=" in p)
            kv["failed"] = parts[0] == "FAILED"
            net.append(kv)
except OSError:
    pass
if net:
    summary["network"] = {}
    # <dds>-ros2: the topics mapped onto ROS 2 (BENCH_ROS2=1), its base horus's own mapping.
    pairs = {"dds": [("raw-cyclone", "horus-cyclonedds"), ("raw-fastdds", "horus-fastdds"),
                     ("horus-cyclonedds", "horus-cyclonedds-ros2"), ("horus-fastdds", "horus-fastdds-ros2")],
             "lcm": [("raw-lcm", "horus-lcm")]}
    for setting in ("local", "netns"):
        lat_rows, tput_rows = [], []
        for suite, impl_pairs in pairs.items():
            for raw, ours in impl_pairs:
                for typ in ("cmdvel", "kilobyte", "image"):
                    def pick(impl, mode):
                        return [r for r in net if r.get("suite") == suite and r.get("setting") == setting
                                and r.get("impl") == impl and r.get("type") == typ and not r["failed"]
                                and (r.get("mode") == "tput") == (mode == "tput")]
                    raw_l, our_l = pick(raw, "lat"), pick(ours, "lat")
                    if raw_l and our_l and all("p50_ns" in r for r in raw_l + our_l):
                        rp = [float(r["p50_ns"]) / 1000 for r in raw_l]
                        hp = [float(r["p50_ns"]) / 1000 for r in our_l]
                        # the ratio of each round's pair (they alternate), then its median
                        ratios = [h / r for h, r in zip(hp, rp) if r > 0]
                        lat_rows.append([suite, ours.replace("horus-", ""), typ, spread(rp), spread(hp), spread(ratios, 2) + "x"])
                        summary["network"][f"{setting}/{suite}/{ours}/{typ}/p50_ratio"] = stats(ratios)
                    raw_t, our_t = pick(raw, "tput"), pick(ours, "tput")
                    if raw_t and our_t:
                        rr = [float(r["rate"]) for r in raw_t]
                        hr = [float(r["rate"]) for r in our_t]
                        ratio = statistics.median(hr) / statistics.median(rr) if statistics.median(rr) > 0 else 0
                        rm = [float(r.get("mbps", 0)) for r in raw_t]
                        hm = [float(r.get("mbps", 0)) for r in our_t]
                        tput_rows.append([suite, ours.replace("horus-", ""), typ, spread(rr, 0), spread(hr, 0),
                                          spread(rm, 1), spread(hm, 1), f"{ratio:.2f}x"])
                        summary["network"][f"{setting}/{suite}/{ours}/{typ}/tput_ratio"] = ratio
        where = "one host (loopback)" if setting == "local" else "two namespace hosts (veth)"
        if lat_rows:
            table(f"network latency p50 (one-way, us), {where}: median (min-max) over rounds "
                  "(rows <dds>-ros2: the raw column is horus's own mapping)",
                  ["suite", "library", "type", "raw", "horus", "horus/raw"], lat_rows)
        if tput_rows:
            table(f"network throughput, reliable, back to back (one run of each; the scripts measure throughput once), {where}",
                  ["suite", "library", "type", "raw msg/s", "horus msg/s", "raw MB/s", "horus MB/s", "horus/raw"], tput_rows)
    failed = [r for r in net if r["failed"]]
    if failed:
        print(f"\n{len(failed)} network runs FAILED: " + "; ".join(f'{r.get("suite")}/{r.get("setting")}/{r.get("impl")}/{r.get("type")}' for r in failed))

# bench/fleet/hybrid.sh --results: per run "backend holder round" and p50 p99 p99.9 (us) of the
# host topic's subscriber, the fleet topic's local subscriber and the other host's.
hybrid_path = os.path.join(out_dir, "hybrid.txt")
if os.path.exists(hybrid_path):
    def num(x):
        try:
            return float(x)
        except ValueError:
            return None
    runs = {}
    with open(hybrid_path) as fh:
        for line in fh:
            f = line.split()
            if len(f) == 12:
                runs.setdefault((f[0], f[1]), []).append([num(x) for x in f[3:]])
    rows = []
    summary["hybrid"] = {}
    who = {"publisher": "the publisher", "subscriber": "the local subscriber", "third": "a third process"}
    for (backend, holder), v in runs.items():
        entry = {}
        for i, sub in enumerate(["host topic", "fleet, local", "fleet, other host"]):
            cols = [[r[3 * i + k] for r in v] for k in range(3)]
            entry[sub] = {q: stats(c) for q, c in zip(["p50_us", "p99_us", "p999_us"], cols)}
            rows.append([backend, who.get(holder, holder), sub] + [spread(c) for c in cols])
        ratios = [r[3] / r[0] for r in v if r[3] and r[0]]  # local p50 / host p50
        entry["local_over_host_p50"] = stats(ratios)
        rows.append([backend, who.get(holder, holder), "local / host (p50)", spread(ratios, 2), "", ""])
        summary["hybrid"][f"{backend}/{holder}"] = entry
    table("fleet topics on the local path (bench/fleet/hybrid.sh: Pose2D at 1 kHz, subscribers blocked in recv_for, "
          "one-way us): median (min-max) over rounds, by who holds the publishing host's bridge",
          ["backend", "bridge held by", "subscriber", "p50", "p99", "p99.9"], rows)

# bench/net_wakeups.sh: context switches per round trip, horus against the raw libraries
wakeups_path = os.path.join(out_dir, "net_wakeups.txt")
if os.path.exists(wakeups_path):
    with open(wakeups_path) as fh:
        text = fh.read().rstrip()
    print("\n" + text)
    md.append("\n**where the network latency goes (bench/net_wakeups.sh)**\n\n```\n" + text + "\n```")
    summary["net_wakeups"] = text

# horus-ros2-convert: a topic mapped onto ROS 2 pays its conversion per message (the table it prints)
convert_path = os.path.join(out_dir, "ros2_convert.txt")
if os.path.exists(convert_path):
    with open(convert_path) as fh:
        text = "\n".join(l for l in fh.read().splitlines() if not l.startswith("RESULT")).strip()
    print("\nROS 2 conversion (horus-ros2-convert)\n" + text)
    md.append("\n**the conversion of a topic mapped onto ROS 2 (horus-ros2-convert)**\n\n```\n" + text + "\n```")
    summary["ros2_convert"] = text

with open(os.path.join(out_dir, "summary.json"), "w") as fh:
    json.dump(summary, fh, indent=1)
with open(os.path.join(out_dir, "summary.md"), "w") as fh:
    fh.write("\n".join(md) + "\n")

# -- plots -------------------------------------------------------------------------------------
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("\nplots skipped: python3-matplotlib is not installed (scripts/bench.sh installs it)")
    sys.exit(0)


def median_round(rounds, key_fn):
    """The round whose key is the median (its CDF stands for the run)."""
    ranked = sorted(rounds, key=key_fn)
    return ranked[len(ranked) // 2]


def cdf_plot(path, title, curves):
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for label, pts in curves:
        if not pts:
            continue
        qs = [q for q, _ in pts]
        ns = [v for _, v in pts]
        ax.plot(ns, qs, label=label)
    ax.set_xscale("log")
    ax.set_xlabel("one-way latency, ns (log)")
    ax.set_ylabel("fraction of messages")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")


if local:
    rnd = median_round(local, lambda r: next((x["p50_ns"] for x in r if x["name"] == "horus Topic<CmdVel>"), 0))
    cdf_plot(os.path.join(out_dir, "latency_cdf_threads.png"), "CmdVel between two threads (median round)",
             [(r["name"], r.get("cdf")) for r in rnd if r.get("cdf")])
if shm:
    rnd = median_round(shm, lambda r: r["cmdvel"]["p50"])
    keys = [("floor_one_line", "floor: one line"), ("floor_two_lines", "floor: two lines"), ("cmdvel", "horus CmdVel"),
            ("kib", "horus 1 KiB"), ("image", "horus 1080p image (loan)"), ("iceoryx_16b", "iceoryx 16 B"),
            ("iceoryx_1kib", "iceoryx 1 KiB"), ("iceoryx_image", "iceoryx 6 MB chunk")]
    cdf_plot(os.path.join(out_dir, "latency_cdf_processes.png"), "between two processes, shared memory (median round)",
             [(label, rnd[k]["cdf"]) for k, label in keys if k in rnd and "cdf" in rnd[k]])
if fanout and fanout.get("fanout_latency"):
    fl = fanout["fanout_latency"]
    n = [r["subscribers"] for r in fl]
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(n, [statistics.median(r["p50_ns"]) / 1000 for r in fl], "o-", label="horus p50 (each subscriber)")
    ax.plot(n, [statistics.median(r["p99_ns"]) / 1000 for r in fl], "s--", label="horus p99")
    ax.plot(n, [statistics.median(r["all_p50_ns"]) / 1000 for r in fl], "^-", label="horus p50, all delivered")
    if all("futex_all_p50_ns" in r for r in fl):
        ax.plot(n, [statistics.median(r["futex_all_p50_ns"]) / 1000 for r in fl], "v:",
                label="raw futex wake of N sleepers, p50 all delivered (the floor)")
    if all("iox_all_p50_ns" in r for r in fl):
        ax.plot(n, [statistics.median(r["iox_all_p50_ns"]) / 1000 for r in fl], "D-.",
                label="iceoryx 2.0 (WaitSet), p50 all delivered")
    ax.plot([2, 4, 8], [0.198, 0.236, 0.276], "kx:", label="HORUS (Rust), published, spinning, i7-10750H")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("subscriber processes")
    ax.set_ylabel("latency, us (log)")
    ax.set_title("fan-out: receivers blocked in recv_for")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(out_dir, "fanout.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")
# horus against its baselines: each bar a p50 ratio (below 1: horus is faster)
bars = []
if local:
    v = [next((x["ratio"] for x in r if x["name"] == "horus Topic<CmdVel>"), None) for r in local]
    b = [next((x["ratio"] for x in r if x["name"] == "boost spsc_queue<CmdVel>"), None) for r in local]
    bars += [("threads: horus / boost", statistics.median([x / y for x, y in zip(v, b) if x and y]))]
if shm and "vs_iceoryx" in shm[0]:
    bars += [("processes: horus / iceoryx, CmdVel", 1 / statistics.median([r["vs_iceoryx"]["cmdvel"] for r in shm if "vs_iceoryx" in r]))]
for key, val in summary.get("network", {}).items():
    if key.endswith("p50_ratio") and val:
        setting, suite, impl, typ, _ = key.split("/")
        bars.append((f"{setting} {impl} {typ}: horus / raw", val["median"]))
if bars:
    fig, ax = plt.subplots(figsize=(8, 0.35 * len(bars) + 1.2))
    ax.barh([b[0] for b in bars], [b[1] for b in bars])
    ax.axvline(1.0, color="k", lw=0.8)
    ax.set_xlabel("p50 ratio (below 1: horus faster)")
    ax.set_title("horus against the baselines, same run")
    ax.invert_yaxis()
    ax.tick_params(axis="y", labelsize=7)
    fig.tight_layout()
    path = os.path.join(out_dir, "baselines.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")
