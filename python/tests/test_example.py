"""examples/python/monitor.py, the Python monitor of the fleet demo, with C++ robots: on one
host they meet in shared memory; on namespace hosts (scripts/fleet-demo.sh --python) through
the fleet backend that examples/fleet.yaml chooses."""

import os
import re
import subprocess
import sys

import pytest
from conftest import program

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
MONITOR = os.path.join(ROOT, "examples", "python", "monitor.py")


def rows(output, robot):
    """The table rows of `robot`: (alive, x, pose Hz)."""
    out = []
    for line in output.splitlines():
        cells = line.split()
        if cells and cells[0] == robot and len(cells) == 8:
            out.append((cells[1], cells[3], float(cells[6])))
    return out


def test_the_python_monitor_shows_cpp_robots_on_this_host(peer, unique):
    demo = program("FLEET_DEMO")
    env = {"HORUS_NAMESPACE": unique.replace(".", "_")[:40], "HORUS_BACKEND": "shm"}
    robots = [subprocess.Popen([demo, "--role", "robot", "--id", str(i), "--duration", "8"],
                               env=dict(os.environ, **env), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
              for i in (1, 2)]
    try:
        out = subprocess.run([sys.executable, MONITOR, "--robots", "2", "--duration", "3"], env=dict(os.environ, **env),
                             capture_output=True, text=True, timeout=60)
    finally:
        for r in robots:
            r.terminate()
            r.wait(timeout=10)
            r.stderr.close()
    assert out.returncode == 0, out.stdout + out.stderr
    assert "poses on shm (host scope)" in out.stdout
    for robot in ("robot_1", "robot_2"):
        last = rows(out.stdout, robot)[-1]
        assert last[0] == "yes" and 5 <= last[2] <= 40, out.stdout  # the robots send 20 poses a second
    assert re.search(r"received \d+ poses from 2 robots; 0 silent", out.stdout)


def test_the_python_monitor_sees_robots_on_other_namespace_hosts():
    if os.geteuid() != 0:
        pytest.skip("namespace hosts need root")
    program("FLEET_DEMO")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("HORUS_", "LCM_", "CYCLONEDDS_"))}
    out = subprocess.run([os.path.join(ROOT, "scripts", "fleet-demo.sh"), "--python", "--no-build", "--no-cut",
                          "--duration", "6"], capture_output=True, text=True, timeout=120, cwd=ROOT, env=env)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "poses on cyclonedds (fleet scope)" in out.stdout
    for robot in ("robot_1", "robot_2"):
        last = rows(out.stdout, robot)[-1]
        assert last[0] == "yes" and last[2] > 5, out.stdout
    assert "0 silent" in out.stdout
    for host in ("robot1", "robot2"):  # horus.Fleet's events, from the fleet's thread
        assert f"fleet: host {host} joined" in out.stdout, out.stdout
