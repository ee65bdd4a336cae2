#!/usr/bin/env python3
"""A live table of a fleet's poses, in Python: the monitor of the fleet demo.

Robots (examples/fleet_demo.cpp, `fleet_demo --role robot --id I`) publish Heartbeat on
fleet.robot_<i>.heartbeat and Pose2D on fleet.robot_<i>.pose. This monitor subscribes to both
for robots 1..N on a horus.Executor and prints the fleet every second. Where the topics travel
is not in this code: shared memory on one host, or the fleet backend that HORUS_CONFIG
(examples/fleet.yaml) or HORUS_BACKEND chooses when the robots are on other hosts; then a
horus.Fleet reports the hosts that join, are lost and rejoin.

    PYTHONPATH=build/default/python python3 examples/python/monitor.py --robots 3 --duration 10
"""

import argparse
import signal
import time

import horus


class Robot:
    def __init__(self, i):
        self.name = f"robot_{i}"
        self.pose = None
        self.poses = 0
        self.poses_at_last_print = 0
        self.heartbeat = None
        self.heartbeat_at = None

    def on_pose(self, pose):
        self.pose = pose
        self.poses += 1

    def on_heartbeat(self, hb):
        self.heartbeat = hb
        self.heartbeat_at = time.monotonic()

    def alive(self, now):
        return self.heartbeat_at is not None and now - self.heartbeat_at < 2.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robots", type=int, default=3, help="robots 1..N")
    ap.add_argument("--duration", type=float, default=None, help="seconds (default: until Ctrl-C)")
    ap.add_argument("--interval", type=float, default=1.0, help="seconds between tables")
    args = ap.parse_args()

    ex = horus.Executor()
    robots = [Robot(i) for i in range(1, args.robots + 1)]
    pose_topics = []
    for i, r in enumerate(robots, start=1):
        pose_topics.append(ex.topic(ex.subscribe(f"fleet.robot_{i}.pose", horus.msg.Pose2D, r.on_pose)))
        ex.subscribe(f"fleet.robot_{i}.heartbeat", horus.msg.Heartbeat, r.on_heartbeat)
    start = time.monotonic()
    scope = pose_topics[0].scope if pose_topics else "host"
    print(f"horus fleet monitor (Python): {args.robots} robots, poses on {pose_topics[0].backend if pose_topics else '-'}"
          f" ({scope} scope)", flush=True)

    def table():
        now = time.monotonic()
        print(f"\nt = {now - start:5.1f} s")
        print(f"{'robot':<9} {'alive':>5} {'hb seq':>6} {'x [m]':>8} {'y [m]':>8} {'th [rad]':>9} {'pose Hz':>8} {'drops':>6}")
        for r, topic in zip(robots, pose_topics):
            p = r.pose
            hz = (r.poses - r.poses_at_last_print) / args.interval
            r.poses_at_last_print = r.poses
            cells = (f"{p.x:8.2f} {p.y:8.2f} {p.theta:9.2f}" if p is not None else f"{'-':>8} {'-':>8} {'-':>9}")
            seq = r.heartbeat.sequence if r.heartbeat is not None else "-"
            print(f"{r.name:<9} {'yes' if r.alive(now) else 'no':>5} {seq:>6} {cells} {hz:8.1f} {topic.dropped_count():>6}",
                  flush=True)

    fleet = None
    if scope == "fleet":  # the poses cross hosts: say when a host joins, is lost or rejoins
        fleet = horus.Fleet()

        def on_host(event):  # runs on the fleet's own thread
            if event.kind != "changed":
                print(f"fleet: host {event.host.name} {event.kind}", flush=True)
        fleet.on_change(on_host)

    ex.every(args.interval, table)
    signal.signal(signal.SIGINT, lambda *_: ex.stop())
    signal.signal(signal.SIGTERM, lambda *_: ex.stop())
    ex.spin(args.duration)
    silent = sum(1 for r in robots if r.poses == 0)
    print(f"\nreceived {sum(r.poses for r in robots)} poses from {args.robots - silent} robots; {silent} silent")
    return 0 if silent == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
