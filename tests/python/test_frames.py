"""Chain.frame: byte-level CS frames from anything with the buffer protocol (bytes, bytearray,
memoryview, numpy arrays) or a list of ints, into a new bytes object or a caller's buffer."""
import numpy
import pytest

import l6470emu


def get_status_frames(chain, make):
    chain.frame(make([0xD0, 0xD0, 0xD0]))
    return chain.frame(make([0, 0, 0])), chain.frame(make([0, 0, 0]))


@pytest.mark.parametrize("make", [
    bytes, bytearray, lambda b: memoryview(bytes(b)), list, tuple,
    lambda b: numpy.array(b, dtype=numpy.uint8), lambda b: numpy.array(b, dtype=numpy.int8 if max(b) < 128 else numpy.uint8),
    lambda b: memoryview(bytes(b)).cast("c"),
], ids=["bytes", "bytearray", "memoryview", "list", "tuple", "numpy-uint8", "numpy-int8", "memoryview-c"])
def test_a_frame_takes_any_bytes_like_input(make):
    chain = l6470emu.Chain(3)
    assert get_status_frames(chain, make) == (b"\x7C\x7C\x7C", b"\x03\x03\x03")


def test_strided_numpy_views_are_read_element_by_element():
    chain = l6470emu.Chain(3)
    data = numpy.array([0xD0, 0xFF, 0xD0, 0xFF, 0xD0, 0xFF], dtype=numpy.uint8)[::2]
    assert not data.flags.contiguous
    chain.frame(data)
    assert chain.frame(numpy.zeros(3, dtype=numpy.uint8)) == b"\x7C\x7C\x7C"


def test_the_answer_can_go_into_a_callers_buffer():
    chain = l6470emu.Chain(2)
    chain.frame(b"\xD0\xD0")
    out = bytearray(2)
    assert chain.frame(b"\x00\x00", out=out) is out and out == b"\x7C\x7C"
    arr = numpy.zeros(4, dtype=numpy.uint8)
    chain.frame(b"\xD0\xD0")
    chain.frame(b"\x00\x00")
    chain.frame(b"\x00\x00", out=arr[::2])
    assert list(arr) == [3, 0, 3, 0]


def test_an_empty_frame_is_a_cs_pulse():
    assert l6470emu.Chain().frame(b"") == b""


@pytest.mark.parametrize("data, error, message", [
    (numpy.zeros(2, dtype=numpy.float64), ValueError, "format"),
    (numpy.zeros((2, 2), dtype=numpy.uint8), ValueError, "one-dimensional"),
    (numpy.zeros(2, dtype=numpy.uint16), ValueError, "uint8"),
    ("D0", TypeError, "str is not bytes"),
    ([0xD0, 256], ValueError, r"frame data\[1\] = 256 is out of range 0..255"),
    ([0xD0, "x"], TypeError, "an int is needed"),
    (3, TypeError, "bytes, bytearray"),
], ids=["float64", "2-D", "uint16", "str", "256", "not-int", "int"])
def test_input_that_is_not_bytes_is_refused_before_the_chain_sees_it(data, error, message):
    chain = l6470emu.Chain(2)
    with pytest.raises(error, match=message):
        chain.frame(data)
    assert chain.get_status(0) == 0x7C03  # nothing reached the chips


@pytest.mark.parametrize("out, error, message", [
    (bytes(2), TypeError, "read-only"),
    (bytearray(3), ValueError, "holds 3 bytes, the frame has 2"),
    (numpy.zeros(2, dtype=numpy.int32), ValueError, "format"),
    ([0, 0], TypeError, "writable buffer"),
], ids=["bytes", "length", "int32", "list"])
def test_a_wrong_output_buffer_is_refused_before_the_frame(out, error, message):
    chain = l6470emu.Chain(2)
    with pytest.raises(error, match=message):
        chain.frame(b"\xD0\xD0", out=out)
    assert chain.get_status(0) == 0x7C03  # the GetStatus opcode was never clocked in
