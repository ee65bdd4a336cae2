"""horus.Topic from Python: the Topic API of C++ (send, try_send, send_blocking, recv,
recv_for, read_latest, the counts), waits that release the GIL, iteration, asyncio, WaitSet,
Executor, and errors that carry the C++ message and code."""

import asyncio
import signal
import sys
import threading
import time

import horus
import pytest

Pose = horus.msg.Pose2D


def test_send_recv_and_the_counts_follow_the_cpp_semantics(unique):
    pub = horus.Topic(unique, Pose, capacity=4)
    sub = horus.Topic(unique, Pose, capacity=4)
    assert pub.capacity == 4 and pub.scope == "host" and pub.backend == "shm" and pub.type is Pose
    assert sub.recv() is None
    for i in range(6):  # two more than the ring holds: the oldest two are lost and counted
        pub.send(Pose(x=float(i)))
    assert sub.pending_count() == 4 and sub.has_message()
    assert [sub.recv().x for _ in range(4)] == [2.0, 3.0, 4.0, 5.0]
    assert sub.dropped_count() == 2
    pub.send(Pose(x=9.0))
    assert sub.read_latest().x == 9.0 and sub.read_latest().x == 9.0
    assert sub.recv() is None  # read_latest counted it as read
    m = pub.metrics()
    assert m["sent"] == 7 and sub.metrics()["received"] == 4
    assert pub.pub_count >= 1 and pub.sub_count == 1


def test_a_verbose_topic_logs_each_send_and_receive(unique, capfd):
    pub = horus.Topic(unique, Pose, verbose=True, log_rate_hz=0)
    sub = horus.Topic(unique, Pose, verbose=True, log_level="warn", log_rate_hz=0)
    pub.send(Pose(x=1.5))
    assert sub.recv().x == 1.5
    err = capfd.readouterr().err
    assert f"[info] topic '{unique}' send #1: Pose2D {{ x: 1.5, y: 0, theta: 0, timestamp_ns: 0 }}" in err
    assert f"[warning] topic '{unique}' recv #1: Pose2D {{ x: 1.5," in err
    with pytest.raises(ValueError, match="log_level: 'loud' is not valid"):
        horus.Topic(unique, Pose, log_level="loud")
    with pytest.raises(TypeError, match="verbose"):
        horus.Topic(unique, Pose, verbose="yes")


def test_try_send_and_send_blocking_wait_for_a_slow_subscriber(unique):
    pub = horus.Topic(unique, Pose, capacity=2)
    sub = horus.Topic(unique, Pose, capacity=2)
    assert pub.try_send(Pose(x=1.0)) and pub.try_send(Pose(x=2.0))
    assert not pub.try_send(Pose(x=3.0))  # the subscriber would lose one
    with pytest.raises(horus.TimeoutError, match="") as e:
        pub.send_blocking(Pose(x=3.0), 0.05)
    assert e.value.code == "timeout"

    start = threading.Event()

    def drain():
        start.wait(5)
        sub.recv()
    switch = sys.getswitchinterval()
    sys.setswitchinterval(10.0)  # the drainer runs only when send_blocking gives the GIL up
    try:
        threading.Thread(target=drain).start()
        start.set()
        pub.send_blocking(Pose(x=3.0), 2.0)  # the GIL is released while it waits for the reader
    finally:
        sys.setswitchinterval(switch)
    assert [sub.recv().x, sub.recv().x] == [2.0, 3.0]


def test_recv_for_releases_the_gil_another_thread_runs_meanwhile(unique):
    sub = horus.Topic(unique, Pose)
    pub = horus.Topic(unique, Pose)
    ticks = [0]
    done = threading.Event()

    def spin():  # counts as fast as the GIL lets it
        while not done.is_set():
            ticks[0] += 1
    t = threading.Thread(target=spin)
    t.start()
    start = time.monotonic()
    before = ticks[0]
    assert sub.recv_for(0.3) is None
    during = ticks[0] - before
    waited = time.monotonic() - start
    done.set()
    t.join()
    assert waited >= 0.29
    assert during >= 10000  # a thread that could not take the GIL while recv_for waited would not count
    threading.Timer(0.05, lambda: pub.send(Pose(x=5.0))).start()
    assert sub.recv_for(5.0).x == 5.0  # wakes when the message comes, not at the timeout


def test_a_wrong_type_on_an_existing_topic_raises_the_cpp_message(unique):
    first = horus.Topic(unique, Pose)  # the topic exists while a handle is open
    with pytest.raises(horus.TypeMismatchError) as e:
        horus.Topic(unique, horus.msg.CmdVel)
    assert e.value.code == "type_mismatch" and isinstance(e.value, TypeError)
    assert f"topic '{unique}' carries horus::msg::Pose2D" in str(e.value)
    assert "cannot open it as horus::msg::CmdVel" in str(e.value)
    first.close()
    assert horus.Topic(unique, horus.msg.CmdVel).type is horus.msg.CmdVel  # gone with its last handle


def test_bad_names_options_and_timeouts_raise_naming_what_was_wrong(unique):
    with pytest.raises(horus.InvalidNameError, match="topic name"):
        horus.Topic("bad name!", Pose)
    with pytest.raises(horus.InvalidArgumentError, match="power of two"):
        horus.Topic(unique, Pose, capacity=3)
    with pytest.raises(TypeError, match="unknown option 'capactiy'; the options are capacity"):
        horus.Topic(unique, Pose, capactiy=4)
    with pytest.raises(ValueError, match="reliability: 'sometimes' is not valid"):
        horus.Topic(unique, Pose, reliability="sometimes")
    with pytest.raises(horus.ConfigError, match="HORUS_BACKEND"):
        horus.Topic(unique, Pose, backend="carrier-pigeon")
    with pytest.raises(TypeError, match="expected a message class of horus.msg"):
        horus.Topic(unique, dict)
    with pytest.raises(ValueError, match="recv_for.timeout.: seconds, a finite number of 0 or more"):
        horus.Topic(unique, Pose).recv_for(-1)
    assert horus.Topic(unique, "Pose2D").type is Pose  # a type by name
    with pytest.raises(ValueError, match="scope 'process' does not go with backend 'cyclonedds'"):
        horus.Topic(unique + ".x", Pose, scope="process", backend="cyclonedds")


def test_a_fleet_scope_without_a_backend_names_where_to_choose_one(unique, monkeypatch):
    monkeypatch.delenv("HORUS_BACKEND", raising=False)
    monkeypatch.delenv("HORUS_CONFIG", raising=False)
    with pytest.raises(horus.ConfigError, match="scope 'fleet' needs a network backend: pass backend="):
        horus.Topic(unique, Pose, scope="fleet")
    monkeypatch.setenv("HORUS_BACKEND", "cyclonedds")
    assert horus.Topic(unique, Pose, scope="fleet").backend == "cyclonedds"


def test_ros2_maps_a_topic_onto_the_ros2_graph_and_checks_what_it_is_given(unique, monkeypatch):
    monkeypatch.delenv("HORUS_BACKEND", raising=False)
    monkeypatch.delenv("HORUS_CONFIG", raising=False)
    # A mapped topic is a fleet topic on DDS (Cyclone DDS without a scope chosen).
    cmd = horus.Topic(unique + ".cmd_vel", horus.msg.CmdVel, ros2={"name": "/py_cmd_vel", "qos": "default"})
    assert cmd.backend == "cyclonedds"
    cmd.close()
    assert horus.Topic(unique + ".off", Pose, ros2=False).backend == "shm"
    with pytest.raises(ValueError, match="ros2: ROS 2 topic name '/1st' has a token that starts with a digit"):
        horus.Topic(unique + ".a", Pose, ros2={"name": "/1st"})
    with pytest.raises(ValueError, match="unknown key 'nmae' in ros2"):
        horus.Topic(unique + ".b", Pose, ros2={"nmae": "/x"})
    with pytest.raises(TypeError, match="ros2"):
        horus.Topic(unique + ".c", Pose, ros2=3)
    with pytest.raises(horus.ConfigError, match="does not convert to geometry_msgs/msg/Twist"):
        horus.Topic(unique + ".d", Pose, ros2={"type": "geometry_msgs/msg/Twist"})
    with pytest.raises(horus.ConfigError, match="ROS 2 nodes speak DDS"):
        horus.Topic(unique + ".e", Pose, ros2=True, backend="lcm")


def test_in_process_topics_and_iteration(unique):
    pub = horus.Topic(unique, Pose, scope="process")
    sub = horus.Topic(unique, Pose, scope="process")
    assert pub.scope == "process"
    for i in range(3):
        pub.send(Pose(x=float(i)))
    got = []
    for msg in sub:  # blocks for each next message
        got.append(msg.x)
        if len(got) == 3:
            break
    assert got == [0.0, 1.0, 2.0]


def test_a_blocking_wait_is_interrupted_by_ctrl_c(unique):
    sub = horus.Topic(unique, Pose)
    threading.Timer(0.2, lambda: signal.raise_signal(signal.SIGINT)).start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        sub.recv_for(None)
    assert time.monotonic() - start < 2.0


def test_asyncio_awaits_messages_without_blocking_the_loop(unique):
    pub = horus.Topic(unique, Pose)
    sub = horus.Topic(unique, Pose)

    async def main():
        ticks = 0

        async def ticker():
            nonlocal ticks
            while True:
                ticks += 1
                await asyncio.sleep(0.01)
        t = asyncio.create_task(ticker())
        asyncio.get_running_loop().call_later(0.2, pub.send, Pose(x=4.0))
        got = await sub.recv_async(timeout=5.0)
        none = await sub.recv_async(timeout=0.05)
        t.cancel()
        return got, none, ticks
    got, none, ticks = asyncio.run(main())
    assert got.x == 4.0 and none is None and ticks >= 10


def test_a_waitset_returns_the_topics_and_triggers_that_are_ready(unique):
    a = horus.Topic(unique + ".a", Pose)
    b = horus.Topic(unique + ".b", horus.msg.CmdVel)
    trigger = horus.Trigger()
    ws = horus.WaitSet()
    for x in (a, b, trigger):
        ws.attach(x)
    assert len(ws) == 3 and ws.wait(0.05) == []
    horus.Topic(unique + ".b", horus.msg.CmdVel).send(horus.msg.CmdVel(linear=1.0))
    ready = ws.wait(1.0)
    assert ready == [b]
    threading.Timer(0.05, trigger.fire).start()
    b.recv()
    assert ws.wait(2.0) == [trigger]


def test_the_executor_runs_callbacks_and_timers_until_stopped(unique):
    ex = horus.Executor()
    got, ticks = [], []
    enough = threading.Event()

    def check():
        if len(got) >= 5 and len(ticks) >= 4:
            enough.set()
    ex.subscribe(unique, Pose, lambda m: (got.append(m.x), check()))
    pub = horus.Topic(unique, Pose)
    ex.every(0.02, lambda: (ticks.append(time.monotonic()), check()))

    def publish_then_stop():
        for i in range(5):
            pub.send(Pose(x=float(i)))
        enough.wait(5)
        ex.stop()
    threading.Thread(target=publish_then_stop).start()
    ex.spin()
    assert got == [0.0, 1.0, 2.0, 3.0, 4.0]
    assert len(ticks) >= 4 and ex.callbacks_run == len(got) + len(ticks)
    ex.stop()
    start = time.monotonic()
    ex.spin()  # a stop before spin returns at once
    assert time.monotonic() - start < 0.05


def test_an_exception_in_a_callback_ends_spin_and_is_raised(unique):
    ex = horus.Executor()

    def bad(m):
        raise RuntimeError(f"cannot handle {m.x}")
    ex.subscribe(unique, Pose, bad)
    horus.Topic(unique, Pose).send(Pose(x=1.0))
    with pytest.raises(RuntimeError, match="cannot handle 1.0"):
        ex.spin(duration=5.0)


def test_stop_returns_after_the_running_callback_and_remove_ends_a_subscription_at_once(unique):
    ex = horus.Executor()
    pub = horus.Topic(unique, Pose)
    got = []

    def first(m):
        got.append(m.x)
        if len(got) == 1:
            ex.stop()
    ex.subscribe(unique, Pose, first)
    for i in range(5):
        pub.send(Pose(x=float(i)))
    ex.spin(duration=5.0)
    assert got == [0.0]  # the four others wait for the next spin
    ex.stop()
    assert ex.spin_once(1.0) == 0  # a stop not consumed yet: nothing runs, at once
    assert ex.spin_once(0.0) == 4
    once = []
    sid = None

    def one_shot(m):
        once.append(m.x)
        ex.remove(sid)
    sid = ex.subscribe(unique + ".once", Pose, one_shot)
    p2 = horus.Topic(unique + ".once", Pose)
    for i in range(3):
        p2.send(Pose(x=float(i)))
    ex.spin_once(1.0)
    assert once == [0.0]
    ex.subscribe(unique + ".again", Pose, lambda m: ex.spin())
    horus.Topic(unique + ".again", Pose).send(Pose())
    with pytest.raises(RuntimeError, match="called from one of its own callbacks"):
        ex.spin_once(1.0)


def test_closing_a_topic_another_thread_waits_on_is_safe(unique):
    sub = horus.Topic(unique, Pose)
    outcome = []
    waiting = threading.Event()

    def wait():
        waiting.set()
        try:
            outcome.append(sub.recv_for(2.0))
        except ValueError as e:
            outcome.append(str(e))
    t = threading.Thread(target=wait)
    t.start()
    waiting.wait(5)
    sub.close()  # waits for the receiving thread's slice, then closes
    t.join(5)
    assert outcome in ([None], ["this topic was closed"])
    assert sub.closed and "closed" in repr(sub)
    with pytest.raises(ValueError, match="this topic was closed"):
        sub.recv()
