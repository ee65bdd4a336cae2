#!/usr/bin/env python3
"""What `horus foxglove` costs on one host (bench/foxglove/run.sh builds what it needs).

A publisher (horus-fox-bench-peer pub) sends a Pose2D stream (1 kHz) and a 1080p RGB camera
(30 Hz, 6 MB frames through the pool), each stamped with the wall clock at send. Per round:

- latency from that stamp to the receive, p50/p99/p99.9:
  baseline: a plain horus subscriber in another process (horus-fox-bench-peer sub);
  foxglove: Foxglove's own client (@foxglove/ws-protocol over `ws`, tests/interop/foxglove_js)
  subscribed through `horus foxglove`, timed when its frame arrives (before decoding);
  C++ client: a minimal client on Boost.Beast (horus-fox-bench-peer ws), timed the same way:
  what the server adds apart from Node.js and the client library;
- the server's CPU (% of one core, from /proc/PID/stat) with 0, 1 and N clients (default 10)
  subscribed to the Pose2D channel, then N clients to the camera, and the frames they got.

Rounds run one after the other; the summary gives the median and the range over rounds.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CLIENT = os.path.join(ROOT, "tests/interop/foxglove_js/client.mjs")


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def node(args, **kw):
    return subprocess.Popen(["node", CLIENT] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)


def last_json(text, key):
    for line in reversed(text.splitlines()):
        if line.startswith("{") and key in line:
            return json.loads(line)
    raise RuntimeError(f"no {key} in:\n{text[-2000:]}")


def server_cpu(server, url, topic, clients, seconds):
    """Server CPU (% of a core) while `clients` Foxglove clients take `topic` for `seconds`: from
    when the last one says it subscribed to when the first one ends."""
    procs = [node(["latency", url, topic, str(seconds)]) for _ in range(clients)]
    for p in procs:
        line = p.stdout.readline()  # {"subscribed": ...}, or the error that ended it
        if '"subscribed"' not in line:
            raise RuntimeError(f"a client did not subscribe to {topic}: {line}{p.communicate()[0]}")
    c0, t0 = cpu_seconds(server.pid), time.monotonic()
    outs = [procs[0].communicate(timeout=seconds + 60)[0]]
    c1, t1 = cpu_seconds(server.pid), time.monotonic()
    outs += [p.communicate(timeout=seconds + 60)[0] for p in procs[1:]]
    frames = sum(last_json(out, '"frame"')["frame"]["n"] for out in outs)
    return 100.0 * (c1 - c0) / (t1 - t0), frames


def one_round(args, peer, cli, r):
    prefix = f"foxbench{os.getpid()}r{r}"
    pub = subprocess.Popen([peer, "pub", prefix, "1000", "30", "3600"], stderr=subprocess.STDOUT)
    server = subprocess.Popen([cli, "foxglove", "--port", "0", "--topics", prefix + ".**"], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
    try:
        line = server.stdout.readline()
        port = re.search(r"ws://[^:]+:(\d+)", line)
        if not port:
            raise RuntimeError(f"horus foxglove said: {line}")
        url = f"ws://127.0.0.1:{port.group(1)}"
        res = {}
        # The baselines first: the server has no client meanwhile (its idle CPU).
        c0, t0 = cpu_seconds(server.pid), time.monotonic()
        for topic in ("pose", "camera"):
            base = subprocess.run([peer, "sub", prefix, topic, str(args.seconds)], capture_output=True, text=True,
                                  timeout=args.seconds + 30)
            res[topic + "_base"] = json.loads(base.stdout)
        res["cpu_idle"] = 100.0 * (cpu_seconds(server.pid) - c0) / (time.monotonic() - t0)
        # The clients wait for the channel's advertise themselves (the scan finds the topics).
        for topic in ("pose", "camera"):
            fox = node(["latency", url, f"{prefix}.{topic}", str(args.seconds)])
            out = fox.communicate(timeout=args.seconds + 60)[0]
            j = last_json(out, '"frame"')
            res[topic + "_fox"] = j["frame"]
            res[topic + "_take"] = j["server_take"]
            cpp = subprocess.run([peer, "ws", port.group(1), prefix, topic, str(args.seconds)], capture_output=True,
                                 text=True, timeout=args.seconds + 30)
            res[topic + "_cpp"] = json.loads(cpp.stdout)
        res["cpu_pose_1"], res["frames_pose_1"] = server_cpu(server, url, f"{prefix}.pose", 1, args.cpu_seconds)
        res["cpu_pose_n"], res["frames_pose_n"] = server_cpu(server, url, f"{prefix}.pose", args.clients,
                                                             args.cpu_seconds)
        res["cpu_camera_n"], res["frames_camera_n"] = server_cpu(server, url, f"{prefix}.camera", args.clients,
                                                                 args.cpu_seconds)
        return res
    finally:
        server.terminate()
        pub.terminate()
        server.wait(timeout=10)
        pub.wait(timeout=10)


def spread(values, fmt="{:.1f}"):
    return f"{fmt.format(statistics.median(values))} ({fmt.format(min(values))}-{fmt.format(max(values))})"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=5, help="seconds per latency measurement")
    ap.add_argument("--cpu-seconds", type=float, default=5, help="seconds per CPU measurement")
    ap.add_argument("--clients", type=int, default=10)
    ap.add_argument("--peer", required=True)
    ap.add_argument("--cli", required=True)
    args = ap.parse_args()
    rounds = []
    for r in range(args.rounds):
        res = one_round(args, args.peer, args.cli, r)
        rounds.append(res)
        print(f"round {r + 1}: " + json.dumps(res), flush=True)
    print()
    print(f"latency from the publisher's stamp, us ({args.rounds} rounds of {args.seconds:.0f} s; "
          "median of the rounds (range))")
    print(f"{'path':<52} {'p50':>20} {'p99':>20} {'p99.9':>20}")
    rows = [("Pose2D 1 kHz: horus subscriber (baseline)", "pose_base"),
            ("Pose2D 1 kHz: Foxglove client via horus foxglove", "pose_fox"),
            ("  of which: to the server's take", "pose_take"),
            ("Pose2D 1 kHz: C++ client via horus foxglove", "pose_cpp"),
            ("1080p RGB 30 Hz: horus subscriber (baseline)", "camera_base"),
            ("1080p RGB 30 Hz: Foxglove client via horus foxglove", "camera_fox"),
            ("  of which: to the server's take", "camera_take"),
            ("1080p RGB 30 Hz: C++ client via horus foxglove", "camera_cpp")]
    for name, key in rows:
        print(f"{name:<52} " + " ".join(f"{spread([x[key][p] for x in rounds]):>20}"
                                         for p in ("p50_us", "p99_us", "p999_us")))
    for topic in ("pose", "camera"):
        for client, key in (("Foxglove's client (Node.js)", "_fox"), ("C++ client", "_cpp")):
            added = [x[topic + key]["p50_us"] - x[topic + "_base"]["p50_us"] for x in rounds]
            print(f"added over the horus subscriber, p50, {topic}, {client}: {spread(added)} us")
    print()
    print(f"server CPU, % of one core (idle: over the baselines; clients: {args.cpu_seconds:.0f} s each; "
          "median (range)); frames the clients got")
    for name, key, frames in (("idle (no client)", "cpu_idle", None), ("1 client, Pose2D 1 kHz", "cpu_pose_1",
                                                                        "frames_pose_1"),
                              (f"{args.clients} clients, Pose2D 1 kHz", "cpu_pose_n", "frames_pose_n"),
                              (f"{args.clients} clients, 1080p 30 Hz", "cpu_camera_n", "frames_camera_n")):
        got = f"  frames {spread([x[frames] for x in rounds], '{:.0f}')}" if frames else ""
        print(f"{name:<40} {spread([x[key] for x in rounds]):>20}{got}")


if __name__ == "__main__":
    sys.exit(main())
