"""Every standard message type from Python to a C++ process and back, field for field: over
shared memory (the same host), and over Cyclone DDS on loopback (the C++ process in another
shared-memory namespace, as if on another host)."""

import os
import time

import horus
import pytest
from conftest import program
from samples import sample


def round_trip_all(peer, prefix, env, topic_options, deadline_s):
    peer([program("HORUS_DDS_PEER"), "echo", prefix, str(deadline_s + 30)], env=env)
    trips = []
    for cls in horus.message_types():
        m = sample(cls)
        out = horus.Topic(f"{prefix}.{cls.__name__}", cls, **topic_options)
        back = horus.Topic(f"{prefix}.{cls.__name__}.echo", cls, **topic_options)
        assert out.backend == topic_options.get("backend", "shm")
        trips.append([cls, m, out, back, None])
    deadline = time.monotonic() + deadline_s
    waiting = trips
    while waiting and time.monotonic() < deadline:
        for t in waiting:
            t[2].send(t[1])
        waiting[0][4] = waiting[0][3].recv_for(0.05)  # the first echo, or 50 ms, then the others that came
        for t in waiting:
            t[4] = t[4] or t[3].recv()
        waiting = [t for t in waiting if t[4] is None]
    missing = [t[0].__name__ for t in waiting]
    assert not missing, f"no echo of {missing}"
    differ = [f"{t[0].__name__}: sent {t[1]!r}, got {t[4]!r}" for t in trips if t[4] != t[1]]
    assert not differ, "\n".join(differ)
    assert len(trips) == 81


def test_every_type_round_trips_through_a_cpp_process_in_shared_memory(peer, unique):
    round_trip_all(peer, unique, {"HORUS_BACKEND": "shm"}, {}, 20)


def test_every_type_round_trips_through_a_cpp_process_over_cyclone_dds(peer, unique):
    env = {"HORUS_BACKEND": "cyclonedds", "HORUS_NAMESPACE": f"peer{os.getpid()}"}
    round_trip_all(peer, unique, env, {"backend": "cyclonedds"}, 60)


def test_a_message_of_the_wrong_class_is_refused_naming_both(unique):
    t = horus.Topic(unique, horus.msg.Pose2D)
    with pytest.raises(TypeError, match=r"expected a horus.msg.Pose2D .*got CmdVel"):
        t.send(horus.msg.CmdVel())
