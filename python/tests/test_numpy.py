"""Large data as NumPy arrays without a copy: a received image's array views its pool slot in
shared memory, a loan is filled in place, and the rule for an array that outlives its message:
it keeps the slot (pinned, its bytes unchanged) until the array goes."""

import gc
import re

import horus
import numpy as np
import pytest
from conftest import program

ENC = horus.msg.ImageEncoding


def mapping_of(address):
    """The /proc/self/maps line whose range holds `address`."""
    with open("/proc/self/maps") as f:
        for line in f:
            lo, hi = (int(x, 16) for x in line.split()[0].split("-"))
            if lo <= address < hi:
                return line.strip()
    return ""


def in_segment(address, topic):
    """True when `address` is inside the shared-memory segment of `topic` (/dev/shm/horus.<namespace>.<topic>)."""
    return re.search(rf"/dev/shm/horus\.[^./]+\.{re.escape(topic)}$", mapping_of(address)) is not None


def data_address(a):
    return a.__array_interface__["data"][0]


def test_a_received_image_is_a_read_only_view_into_the_topics_shared_memory(unique):
    pub = horus.Topic(unique, horus.msg.Image)
    sub = horus.Topic(unique, horus.msg.Image)
    loan = pub.loan(480, 640, ENC.Rgb8)
    loan.data[:] = np.arange(480 * 640 * 3, dtype=np.uint32).reshape(480, 640, 3) % 251
    pub.send(loan)
    img = sub.recv_for(1.0)
    a = img.data
    assert a.shape == (480, 640, 3) and a.dtype == np.uint8 and not a.flags.writeable
    assert a[479, 639, 2] == (480 * 640 * 3 - 1) % 251
    assert in_segment(data_address(a), unique)
    with pytest.raises(ValueError, match="read-only"):
        a[0, 0, 0] = 1
    copy = img.copy()  # a copy owns its bytes: writable, outside the pool
    assert copy.data.flags.writeable and "/dev/shm" not in mapping_of(data_address(copy.data))


def test_an_image_from_a_cpp_process_arrives_as_a_view_of_its_pool(peer, unique):
    peer([program("HORUS_DDS_PEER"), "echo", unique, "60"], env={"HORUS_BACKEND": "shm"})
    out = horus.Topic(f"{unique}.Image", horus.msg.Image)
    back = horus.Topic(f"{unique}.Image.echo", horus.msg.Image)
    loan = out.loan(1080, 1920, ENC.Rgb8)
    loan.data[:, :, 0] = 9
    loan.data[:, :, 1:] = 4
    loan.message.frame_id = "cam"
    out.send(loan)
    img = back.recv_for(10.0)
    assert img is not None and img.frame_id == "cam" and img.data.shape == (1080, 1920, 3)
    assert (img.data[:, :, 0] == 9).all() and (img.data[:, :, 1:] == 4).all()
    # The C++ echo wrote the bytes into its pool slot of the echo topic: Python reads them there.
    assert in_segment(data_address(img.data), f"{unique}.Image.echo")


def test_a_loan_is_filled_in_place_and_its_arrays_turn_read_only_once_sent(unique):
    pub = horus.Topic(unique, horus.msg.DepthImage)
    sub = horus.Topic(unique, horus.msg.DepthImage)
    loan = pub.loan(4, 6, horus.msg.TensorDtype.F32)
    a = loan.data
    assert a.shape == (4, 6) and a.dtype == np.float32 and a.flags.writeable
    assert in_segment(data_address(a), unique)
    a[:] = 1.25
    pub.send(loan)
    assert loan.sent and not a.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        a[0, 0] = 2.0
    with pytest.raises(ValueError, match="this loan was sent"):
        loan.data
    got = sub.recv_for(1.0)
    assert data_address(got.data) == data_address(a) and (got.data == 1.25).all()
    del got
    pub.close()
    sub.close()
    a.sum()  # the array keeps the memory mapped: reading it never crashes (what it shows is undefined)


def test_an_array_that_outlives_its_message_keeps_the_slot_and_its_bytes(unique):
    pub = horus.Topic(unique, horus.msg.Image, capacity=4)
    sub = horus.Topic(unique, horus.msg.Image, capacity=4)
    kept = []
    for i in range(8):  # a publisher has 2 x capacity pool slots
        loan = pub.loan(8, 8, ENC.Mono8)
        loan.data[:] = i
        pub.send(loan)
        kept.append(sub.recv_for(1.0).data)  # the message itself is gone: the array holds the slot
    gc.collect()
    assert [int(a[0, 0]) for a in kept] == list(range(8))
    with pytest.raises(horus.LimitReachedError, match="every pool slot of this publisher .8. is pinned"):
        pub.loan(8, 8, ENC.Mono8)
    del kept[:4]
    gc.collect()
    for i in range(8, 12):  # the four released slots are lent again; the kept arrays do not change
        loan = pub.loan(8, 8, ENC.Mono8)
        loan.data[:] = i
        pub.send(loan)
        assert int(sub.recv_for(1.0).data[0, 0]) == i
    assert [int(a[0, 0]) for a in kept] == [4, 5, 6, 7]


@pytest.mark.parametrize("make, shape, dtype", [
    (lambda: horus.msg.Image(2, 3, ENC.Mono16), (2, 3), np.uint16),
    (lambda: horus.msg.Image(2, 3, ENC.Rgb32F), (2, 3, 3), np.float32),
    (lambda: horus.msg.DepthImage(2, 3, horus.msg.TensorDtype.U16), (2, 3), np.uint16),
    (lambda: horus.msg.PointCloud(5, 4, horus.msg.TensorDtype.F32), (5, 4), np.float32),
    (lambda: horus.msg.Tensor([2, 3, 4], horus.msg.TensorDtype.F64), (2, 3, 4), np.float64),
])
def test_each_large_type_has_the_shape_and_dtype_its_metadata_says(make, shape, dtype):
    m = make()
    assert m.data.shape == shape and m.data.dtype == dtype and m.data.flags.writeable
    m.data[...] = 3
    assert (m.copy().data == 3).all()


def test_loan_errors_name_the_type_and_the_limit(unique):
    with pytest.raises(TypeError, match="Pose2D is not large data"):
        horus.Topic(unique + "p", horus.msg.Pose2D).loan(1, 2)
    big = horus.Topic(unique, horus.msg.Image)
    with pytest.raises(horus.MessageTooLargeError):
        big.loan(8000, 8000, ENC.Rgb8)
    with pytest.raises(ValueError, match="describe no valid message"):
        big.loan(0, 10, ENC.Rgb8)
