"""The 81 message classes: made from the C++ reflection, with the C++ field names, equality,
repr, to_dict / from_dict, and errors that name the field and what it takes."""

import copy

import horus
import numpy as np
import pytest
from samples import sample


def test_there_are_81_standard_messages_each_default_constructible_with_the_cpp_names():
    classes = horus.message_types()
    assert len(classes) == 81
    for cls in classes:
        m = cls()
        assert cls.type_name == f"horus::msg::{cls.__name__}"
        assert getattr(horus.msg, cls.__name__) is cls
        assert len(cls.fields) > 0
        for f in cls.fields:
            getattr(m, f)
    assert horus.msg.Pose2D.fields == ("x", "y", "theta", "timestamp_ns")
    from horus.msg import Pose2D  # the submodules import as modules
    import horus.record as record
    assert Pose2D is horus.msg.Pose2D and record.Recorder is horus.record.Recorder
    assert horus.msg.Pose2D.type_hash != horus.msg.CmdVel.type_hash


@pytest.mark.parametrize("cls", horus.message_types(), ids=lambda c: c.__name__)
def test_a_message_survives_to_dict_and_from_dict_and_equality_sees_every_field(cls):
    m = sample(cls)
    assert m == cls.from_dict(m.to_dict())
    assert m != cls()
    assert copy.copy(m) == m and copy.deepcopy(m) == m and m.copy() == m
    assert repr(m).startswith(cls.__name__ + "(")


def test_fields_are_attributes_nested_messages_are_views_and_arrays_are_numpy_views():
    odom = horus.msg.Odometry(frame_id="odom")
    odom.pose.x = 2.5
    assert odom.pose.x == 2.5 and odom.frame_id == "odom"
    pose = odom.pose
    del odom  # the view keeps its message alive
    assert pose.x == 2.5
    scan = horus.msg.LaserScan()
    assert isinstance(scan.ranges, np.ndarray) and scan.ranges.shape == (360,)
    scan.ranges[:] = 1.5
    assert scan.to_dict()["ranges"][359] == 1.5
    scan.ranges = [2.0] * 360
    assert scan.ranges[0] == 2.0


def test_keyword_construction_and_the_dict_keep_the_field_order():
    p = horus.msg.Pose2D(x=1.0, y=2.0, theta=0.5, timestamp_ns=7)
    assert list(p.to_dict()) == ["x", "y", "theta", "timestamp_ns"]
    assert p.to_dict() == {"x": 1.0, "y": 2.0, "theta": 0.5, "timestamp_ns": 7}
    assert repr(p) == "Pose2D(x=1.0, y=2.0, theta=0.5, timestamp_ns=7)"


def test_bad_values_raise_naming_the_field_and_what_it_takes():
    with pytest.raises(TypeError, match="Pose2D has no field 'z'; its fields: x, y, theta, timestamp_ns"):
        horus.msg.Pose2D(z=1.0)
    with pytest.raises(ValueError, match=r"Heartbeat.sequence: -1 is out of range for uint64"):
        horus.msg.Heartbeat(sequence=-1)
    with pytest.raises(TypeError, match=r"Pose2D.x: expected a number, got str"):
        horus.msg.Pose2D(x="one")
    with pytest.raises(ValueError, match=r"LaserScan.ranges: 3 elements given; the field has exactly 360"):
        horus.msg.LaserScan(ranges=[1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"holds at most 31"):
        horus.msg.Odometry(frame_id="x" * 40)
    with pytest.raises(ValueError, match=r"Pose2D: Pose2D has no field 'q'"):
        horus.msg.Pose2D.from_dict({"q": 1})


def test_enums_are_classes_of_horus_msg_and_take_names_too():
    img = horus.msg.ImageDescriptor(encoding="Mono16")
    assert img.encoding == horus.msg.ImageEncoding.Mono16
    with pytest.raises(ValueError, match="'Purple' is not one of Mono8, Mono16"):
        horus.msg.ImageDescriptor(encoding="Purple")


def test_generic_message_carries_a_dict_packed_with_messagepack():
    value = {"seq": 3, "pose": [1.5, -2.0], "name": "r1", "ok": True, "none": None, "blob": b"\x00\x01"}
    g = horus.msg.GenericMessage.from_value(value, "meta")
    assert g.to_value() == value and g.metadata == "meta"
    with pytest.raises(ValueError, match="4096"):
        horus.msg.GenericMessage.from_value({"big": "x" * 5000})
    with pytest.raises(TypeError, match="a dict, list, tuple, str, bytes"):
        horus.msg.GenericMessage.from_value({"x": object()})


def test_copies_and_read_only_values_say_so_instead_of_dropping_writes():
    grid = horus.msg.OccupancyGrid(data=[1, 2, 3])
    assert list(grid.data) == [1, 2, 3]
    with pytest.raises(ValueError, match="read-only"):
        grid.data[0] = 5  # a vector comes as a copy: assign the whole field
    js = horus.msg.JointState()
    assert isinstance(js.names, tuple)
    t = horus.msg.Tensor([2, 3], horus.msg.TensorDtype.F32)
    with pytest.raises(ValueError, match="read-only"):
        t.shape[0] = 3  # large data's metadata comes from its constructor
    with pytest.raises(AttributeError, match="read-only"):
        t.ndim = 1


def test_a_bad_element_leaves_the_field_as_it_was():
    scan = horus.msg.LaserScan()
    scan.ranges[:] = 1.0
    values = [2.0] * 360
    values[100] = "far"
    with pytest.raises(TypeError, match=r"LaserScan.ranges\[100\]: expected a number, got str"):
        scan.ranges = values
    assert (scan.ranges == 1.0).all()


def test_a_class_deriving_from_two_messages_is_refused_not_misread():
    class Both(horus.msg.Pose2D, horus.msg.CmdVel):
        def __init__(self):
            horus.msg.Pose2D.__init__(self)
            horus.msg.CmdVel.__init__(self)
    b = Both()
    with pytest.raises(TypeError, match="several horus message classes"):
        b.x
