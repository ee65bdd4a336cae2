"""horus.config (check, explain), horus.record (Recorder, Player: MCAP and LCM logs) and
horus.Fleet from Python, on the same files and settings as the C++ API and the CLI."""

import os
import subprocess

import horus
import pytest
from conftest import program

Pose = horus.msg.Pose2D


def test_config_check_and_explain_read_the_file_as_cpp_does(tmp_path):
    good = tmp_path / "fleet.yaml"
    good.write_text("network:\n  backend: cyclonedds\n"
                    "topics:\n  - match: \"fleet.**\"\n    scope: fleet\n    reliability: reliable\n"
                    "  - match: \"*.camera\"\n    scope: host\n    capacity: 4\n")
    assert horus.config.check(str(good)) == 2
    e = horus.config.explain("fleet.robot_1.pose", file=str(good))
    assert e["scope"]["value"] == "fleet" and e["backend"]["value"] == "cyclonedds"
    assert e["scope"]["from"] == f"file {good}, line 4: rule 'fleet.**'"
    assert e["reliability"]["value"] == "reliable" and e["security"]["mode"] == "off"
    cam = horus.config.explain("robot_1.camera", file=str(good))
    assert cam["scope"]["value"] == "host" and cam["capacity"]["value"] == 4
    bad = tmp_path / "bad.yaml"
    bad.write_text("topics:\n  - match: \"a.*\"\n    scope: galaxy\n")
    with pytest.raises(horus.ConfigError) as err:
        horus.config.check(str(bad))
    assert str(bad) in str(err.value) and "line 3" in str(err.value) and "galaxy" in str(err.value)
    with pytest.raises(horus.InvalidNameError):
        horus.config.explain("bad name", file=str(good))
    verbose = tmp_path / "verbose.yaml"
    verbose.write_text("topics:\n  - match: cmd_vel\n    log: true\n    log_rate_hz: 0\n")
    v = horus.config.explain("cmd_vel", file=str(verbose))
    assert v["verbose"] == {"value": True, "from": f"file {verbose}, line 2: rule 'cmd_vel'"}
    assert v["log_level"]["value"] == "info" and v["log_rate_hz"]["value"] == 0.0
    assert horus.config.explain("odom", file=str(verbose))["verbose"] == {"value": False, "from": "default"}


def test_the_configuration_file_chooses_scopes_in_python_as_in_cpp(tmp_path, unique):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(f"topics:\n  - match: \"{unique}.local\"\n    scope: process\n    capacity: 8\n")
    env = dict(os.environ, HORUS_CONFIG=str(cfg), PYTHONPATH=os.environ.get("PYTHONPATH", ""))
    code = (f"import horus; t = horus.Topic('{unique}.local', horus.msg.Pose2D); "
            f"u = horus.Topic('{unique}.other', horus.msg.Pose2D); print(t.scope, t.capacity, u.scope)")
    out = subprocess.run([os.sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["process", "8", "host"]


@pytest.mark.parametrize("fmt, suffix", [("mcap", "mcap"), ("lcm", "lcm")])
def test_a_recording_made_in_python_plays_back_into_topics(tmp_path, fmt, suffix):
    unique = f"rec{os.getpid()}{fmt}"  # an LCM channel name is at most 63 bytes
    path = str(tmp_path / f"run.{suffix}")
    pub = horus.Topic(unique + ".pose", Pose)
    cmd = horus.Topic(unique + ".cmd", horus.msg.CmdVel)
    with horus.record.Recorder(path, format=fmt) as rec:
        rec.add(unique + ".pose", Pose)
        rec.add(unique + ".cmd", "CmdVel")
        for i in range(20):
            pub.send(Pose(x=float(i), timestamp_ns=1000 + i))
            cmd.send(horus.msg.CmdVel(linear=float(i)))
    stats = rec.stats()  # closed: it took what the topics held
    assert stats["topics"][unique + ".pose"]["messages"] == 20 and stats["messages"] == 40
    player = horus.record.Player(path)
    assert set(player.topics) == {unique + ".pose", unique + ".cmd"}
    sub = horus.Topic(unique + ".replayed", Pose, capacity=32)
    player.bind(unique + ".pose", to=unique + ".replayed")
    played = player.play(rate=0)
    assert played["published"] == 20 and played["failed"] == 0
    assert [sub.recv().x for _ in range(20)] == [float(i) for i in range(20)]
    assert player.topics[unique + ".cmd"] is horus.msg.CmdVel  # MCAP: its type; LCM: by fingerprint
    if fmt == "mcap":  # an LCM log carries no type hash: a wrong type fails message by message
        with pytest.raises(horus.TypeMismatchError, match="type hash"):
            horus.record.Player(path).bind(unique + ".cmd", Pose, to=unique + ".wrong")
    with pytest.raises(horus.Error):
        horus.record.Player(str(tmp_path / "missing.mcap"))


def test_a_ros2_bag_made_in_python_plays_back_through_the_conversion(tmp_path, unique):
    path = str(tmp_path / "ros2.mcap")
    pub = horus.Topic(unique + ".pose", Pose)
    with horus.record.Recorder(path, profile="ros2") as rec:
        rec.add(unique + ".pose", Pose)
        for i in range(5):
            pub.send(Pose(x=float(i), theta=0.5))
    ros_name = "/" + unique.replace(".", "/") + "/pose"
    player = horus.record.Player(path)
    assert player.topics == {ros_name: Pose}  # geometry_msgs/msg/Pose2D, played as a Pose2D
    sub = horus.Topic(unique + ".back", Pose, capacity=8)
    player.bind(ros_name, to=unique + ".back")
    assert player.play(rate=0)["published"] == 5
    got = [sub.recv() for _ in range(5)]
    assert [m.x for m in got] == [0.0, 1.0, 2.0, 3.0, 4.0] and got[0].theta == 0.5
    with pytest.raises(horus.Error, match="ros2"):
        horus.record.Recorder(str(tmp_path / "x.lcm"), format="lcm", profile="ros2")


def test_a_recording_in_python_reads_in_the_cli(tmp_path, unique):
    path = str(tmp_path / "py.mcap")
    pub = horus.Topic(unique, Pose)
    with horus.record.Recorder(path) as rec:
        rec.add(unique, Pose)
        for i in range(5):
            pub.send(Pose(x=float(i)))
    out = subprocess.run([program("HORUS_CLI"), "record", "info", path], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert unique in out.stdout and "horus::msg::Pose2D" in out.stdout


def test_the_fleet_view_shows_this_host_and_its_fleet_topics(unique):
    fleet = horus.Fleet(transport="cyclonedds")
    events = []
    fleet.on_change(events.append)
    t = horus.Topic(unique, Pose, backend="cyclonedds")
    t.send(Pose(x=1.0))
    me = None
    for _ in range(100):
        fleet.refresh()
        me = next((h for h in fleet.hosts() if h.self), None)
        if me is not None and any(x.name == unique for x in me.topics):
            break
        t.recv_for(0.05)
    assert me is not None and me.state == "alive"
    topic = next(x for x in me.topics if x.name == unique)
    assert topic.type_name == "horus::msg::Pose2D" and topic.scope == "fleet" and topic.transport == "cyclonedds"
    assert fleet.transport == "cyclonedds"
    with pytest.raises(horus.ConfigError):
        horus.Fleet(transport="carrier-pigeon")
