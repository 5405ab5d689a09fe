"""Traces from Python: a Chain records itself (into memory or a native file flushed frame by
frame), Trace loads every format the l6470emu program reads, and replay() / decode() run the
library's replay and decoder over a Trace or a file."""
from pathlib import Path

import pytest

import l6470emu
from l6470emu import Reg

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures" / "traces"


def session(chain):
    chain.get_status(1)
    chain.set_param(1, Reg.MAX_SPEED, 0x20)
    chain.move(1, True, 1600)
    chain.set_sw_pin(0, False)
    chain.set_thermal(0, "warning")
    chain.advance(seconds=0.5)
    chain.get_param(1, Reg.ABS_POS)
    chain.frame(b"\xD0\xD0")
    chain.frame(bytes(2))


def test_a_recording_in_memory_replays_without_a_divergence():
    chain = l6470emu.Chain(["L6470", "L6480"], record=True)
    assert chain.recording
    session(chain)
    trace = chain.trace
    assert trace.chain == "L6470,L6480" and trace.frame_count == 3 + 3 + 4 + 4 + 2
    kinds = {e.kind for e in trace}
    assert kinds == {"frame", "pin", "fault"}
    result = l6470emu.replay(trace)
    assert result and result.matched and result.frames == trace.frame_count and result.pin_checks > 0
    assert not result.divergences


def test_a_recording_into_a_file_is_complete_as_it_goes(tmp_path):
    path = tmp_path / "run.trace"
    with l6470emu.Chain(["L6470", "L6480"], record=path) as chain:
        assert chain.record_path == str(path)
        session(chain)
        frames_so_far = sum(line.split()[1:2] == ["frame"] for line in path.read_text().splitlines())
        assert frames_so_far == 16  # flushed frame by frame, before the chain is closed
    assert not chain.recording
    chain.get_status(0)  # still usable, no longer recorded
    assert l6470emu.Trace.load(path).frame_count == 16
    assert l6470emu.replay(path).matched
    assert l6470emu.replay(str(path), chain=["L6470", "L6480"]).matched


def test_decode_explains_every_command_per_chip():
    chain = l6470emu.Chain(2, record=True, check="warn")
    chain.get_status(1)
    chain.move(1, False, 3200)
    with pytest.warns(l6470emu.SanitizerWarning, match="Chain: chip 0: WRONG_CMD: byte 0xEB: reserved opcode"):
        chain.frame(b"\xEB\x00")  # a reserved opcode for chip 0
    result = l6470emu.decode(chain.trace)
    assert "chip 1   Move(REV, 3200 microsteps)" in result.text
    assert "GetStatus" in str(result)
    assert (result.commands, result.answers, result.diagnostics) == (1, 1, 1)  # Move; GetStatus; 0xEB
    only = l6470emu.decode(chain.trace, only_chip=0).text
    assert "Move" not in only


def test_a_diverging_replay_reports_where_and_why():
    chain = l6470emu.Chain(1, record=True)
    chain.move(0, True, 3200)
    chain.set_sw_pin(0, False)
    chain.advance(seconds=0.5)
    chain.get_param(0, Reg.ABS_POS)
    lines = chain.trace.to_native().splitlines()  # edit the last frame's last MISO byte
    last = max(i for i, l in enumerate(lines) if " frame " in l)
    lines[last] = lines[last][:-2] + ("00" if not lines[last].endswith("00") else "01")
    trace = l6470emu.Trace.parse("\n".join(lines) + "\n", name="edited.trace")
    result = l6470emu.replay(trace)
    assert not result and result.divergent_frames == 1 and result.stopped_early
    assert result.divergences[0].summary.startswith("edited.trace:")
    assert "expected" in result.divergences[0].report
    assert l6470emu.replay(trace, keep_going=True).stopped_early is False


@pytest.mark.parametrize("name, chain", [
    ("three_chips.trace", None), ("single_chip.trace", None), ("saleae_logic2.csv", "L6470"),
    ("saleae_logic2_decimal_no_duration.csv", "L6470"),
])
def test_the_fixture_captures_replay_clean(name, chain):
    assert l6470emu.replay(FIXTURES / name, chain=chain).matched
    assert l6470emu.decode(FIXTURES / name, chain=chain).frames > 0


def test_loading_any_format_gives_events_with_their_bytes():
    trace = l6470emu.Trace.load(FIXTURES / "saleae_logic2.csv")
    assert trace.format == "saleae" and trace.chain is None and len(trace) == trace.frame_count
    first = trace[0]
    assert (first.kind, first.mosi, first.miso) == ("frame", b"\xD0", b"\x00")
    assert first.source_time == pytest.approx(0.4218552, abs=1e-6) and first.line == 2
    assert trace[-1].kind == "frame"
    with pytest.raises(IndexError):
        trace[len(trace)]
    with pytest.raises(ValueError, match="names no chain"):
        l6470emu.replay(trace)
    assert l6470emu.replay(trace, chain="L6470").matched
    native = l6470emu.Trace.load(FIXTURES / "three_chips.trace")
    faults = [e for e in native if e.kind == "fault"]
    assert faults and faults[0].fault == "THERMAL" and faults[0].chip == 2
    assert any(e.pin == "SW" for e in native)


def test_a_trace_saved_and_parsed_back_is_the_same(tmp_path):
    trace = l6470emu.Trace.load(FIXTURES / "three_chips.trace")
    trace.save(tmp_path / "copy.trace")
    again = l6470emu.Trace.load(tmp_path / "copy.trace")
    assert again.to_native() == trace.to_native()
    assert l6470emu.Trace.parse(trace.to_native()).frame_count == trace.frame_count


def test_malformed_input_is_a_trace_error_with_file_and_line(tmp_path):
    bad = tmp_path / "bad.trace"
    bad.write_text("l6470emu-trace 1\nchain 1*L6470\n0.001 frame 1us D0 | ZZ\n")
    with pytest.raises(l6470emu.TraceError) as caught:
        l6470emu.replay(bad)
    assert caught.value.file.endswith("bad.trace") and caught.value.line == 3
    assert isinstance(caught.value, ValueError) and "bad.trace:3:" in str(caught.value)
    with pytest.raises(l6470emu.TraceError, match="cannot open"):
        l6470emu.Trace.load(tmp_path / "missing.trace")
    with pytest.raises(l6470emu.TraceError, match="unknown trace format"):
        l6470emu.Trace.parse("hello\n")
    with pytest.raises(ValueError, match="format"):
        l6470emu.Trace.load(bad, format="pcap")
    with pytest.raises(RuntimeError, match="record"):
        l6470emu.Chain(record=tmp_path / "no" / "such" / "dir.trace")


def test_decode_and_replay_number_chips_from_either_end_and_say_which():
    miso = l6470emu.decode(FIXTURES / "three_chips.trace")
    mosi = l6470emu.decode(FIXTURES / "three_chips.trace", number_from="mosi")
    assert miso.number_from == "miso" and "count from the MISO end" in miso.numbering
    assert mosi.number_from == "mosi" and "count from the MOSI end" in mosi.numbering
    # The thermal warning was on the chain's chip 2, nearest the host's MOSI.
    assert "chip 2   fault THERMAL warning" in miso.text
    assert "chip 0   fault THERMAL warning" in mosi.text
    only = l6470emu.decode(FIXTURES / "three_chips.trace", number_from="mosi", only_chip=0).text
    assert "fault THERMAL warning" in only and "chip 2 " not in only
    # Lines of one time come in the user's order.
    at = [line for line in mosi.text.splitlines() if line.startswith("t=0.001047 s")]
    assert [line.split()[3] for line in at] == ["0", "1", "2"]
    result = l6470emu.replay(FIXTURES / "ftrace_spi_set_cs.txt", chain="3", number_from="mosi")
    assert not result.matched and result.number_from == "mosi"
    assert "byte 0: chip 2: byte 3 of 3 of the GetParam(ABS_POS) answer" in result.divergences[0].report


@pytest.mark.parametrize("call", [l6470emu.decode, l6470emu.replay])
def test_an_unknown_numbering_is_a_value_error_naming_the_argument(call):
    with pytest.raises(ValueError, match="number_from: 'x' is not a chip numbering"):
        call(FIXTURES / "three_chips.trace", number_from="x")


def test_a_bad_chain_argument_names_the_argument_not_a_command_line_option():
    with pytest.raises(ValueError, match='^chain: unknown chip variant "L6499"'):
        l6470emu.replay(FIXTURES / "three_chips.trace", chain="3*L6499")


def test_errors_name_the_file_and_line(tmp_path):
    bad = tmp_path / "bad.trace"
    bad.write_text("l6470emu-trace 1\n0.001 frame 00 | 00\n0.002 frame 0G | 00\n")
    with pytest.raises(l6470emu.TraceError) as e:
        l6470emu.decode(bad)
    assert e.value.file == str(bad) and e.value.line == 3
    assert str(e.value) == f'{bad}:3: MOSI "0G" is not a byte (two hex digits)'
    empty = tmp_path / "empty.trace"
    empty.write_bytes(b"")
    with pytest.raises(l6470emu.TraceError, match="empty file"):
        l6470emu.Trace.load(empty)


def test_save_names_the_file_and_the_reason(tmp_path):
    trace = l6470emu.Trace.load(FIXTURES / "three_chips.trace")
    with pytest.raises(RuntimeError, match=f"^{tmp_path}/no/such/dir.trace: cannot create: No such file or directory$"):
        trace.save(tmp_path / "no" / "such" / "dir.trace")
    trace.save(tmp_path / "t.trace.gz")
    assert (tmp_path / "t.trace.gz").read_bytes()[:2] == b"\x1f\x8b"
    assert len(l6470emu.Trace.load(tmp_path / "t.trace.gz")) == len(trace)


BOMB = ("l6470emu-trace 1\nchain L6470\n0.00000000 frame 0.25us 00 | 00\n"
        "1000000.00000000 repeat 1 frame 1000000000000 times every 1.00us\n")


@pytest.mark.parametrize("call", [l6470emu.replay, l6470emu.decode, l6470emu.motion, l6470emu.Trace.load])
def test_a_trace_asking_for_a_trillion_frames_is_refused_at_once_with_the_line(tmp_path, call):
    bomb = tmp_path / "bomb.trace"
    bomb.write_text(BOMB)
    with pytest.raises(l6470emu.TraceError) as e:
        call(bomb)
    assert str(e.value) == (f"{bomb}:4: repeat: 1000000000000 repetitions of 1 frame make the trace 1000000000001 "
                            "frames long: more than 10000000 frames, the limit (raise it with --max-frames N, or "
                            "max_frames=N in Python; 0 = no limit)")
    assert e.value.line == 4
    with pytest.raises(l6470emu.TraceError, match="more than 999 frames, the limit"):
        call(bomb, max_frames=999)


@pytest.mark.parametrize("call", [l6470emu.replay, l6470emu.decode, l6470emu.motion])
def test_max_frames_raises_the_limit_and_counts_repeated_frames(tmp_path, call):
    path = tmp_path / "t.trace"
    path.write_text("l6470emu-trace 1\nchain L6470\n0 frame 0.25us 00 | 00\n0.00000100 frame 0.25us 00 | 00\n"
                    "0.00020100 repeat 2 frames 20 times every 10.00us\n")
    with pytest.raises(l6470emu.TraceError, match=r":5: repeat: 20 repetitions of 2 frames make the trace 42 frames"):
        call(path, max_frames=41)
    call(path, max_frames=42)
    call(path, max_frames=0)  # no limit
    with pytest.raises(ValueError, match="max_frames"):
        call(path, max_frames=-1)
    assert l6470emu.DEFAULT_MAX_FRAMES == 10_000_000


def test_parse_takes_the_same_bound():
    with pytest.raises(l6470emu.TraceError, match=r"bomb:4: repeat: .* more than 10000000 frames"):
        l6470emu.Trace.parse(BOMB, "bomb")
    with pytest.raises(l6470emu.TraceError, match=r"t.csv:\d+: the trace holds more than 2 frames"):
        rows = "".join(f'"SPI","enable",0.{i}1,2e-08,,\n"SPI","result",0.{i}2,1e-06,0xD0,0x00\n'
                       f'"SPI","disable",0.{i}3,2e-08,,\n' for i in range(1, 5))
        l6470emu.Trace.parse('name,type,start_time,duration,"mosi","miso"\n' + rows, "t.csv", max_frames=2)


@pytest.mark.parametrize("points", [2**62, 2**80, 100_001, -1])
def test_motion_refuses_more_points_than_a_picture_can_use(points):
    with pytest.raises(ValueError, match=r"max_points .* out of range 0\.\.100000"):
        l6470emu.motion(FIXTURES / "three_chips.trace", max_points=points)
    assert len(l6470emu.motion(FIXTURES / "three_chips.trace", max_points=l6470emu.MAX_MOTION_POINTS).chips) == 3


HOMING_RIG = "chips=L6470 axis.0=stops=-6400..300000,start=51200,switch=home@0:below:hyst=64"


def test_a_recording_carries_its_world_and_a_foreign_capture_takes_it_as_board(tmp_path):
    # homing_axis.trace: a preloaded python3-spidev homing run against the axis' home switch.
    native = FIXTURES / "homing_axis.trace"
    assert l6470emu.replay(native).matched          # the trace's own board lines: the axis
    decoded = l6470emu.decode(native)
    assert decoded.divergence is None and decoded.frames_diverged == 0 and decoded.pins_diverged == 0
    assert l6470emu.motion(native).divergence is None
    # The same traffic as a Saleae export carries no board: without one the switch never
    # closes, and every result says where the emulator departs from the capture.
    capture = FIXTURES / "homing_axis_saleae.csv"
    bare = l6470emu.decode(capture)
    first = bare.divergence
    assert isinstance(first, l6470emu.FirstDivergence)
    assert first.chip == 0 and first.frame > 0 and first.seconds > 2.0 and "expected" in first.what
    assert bare.frames_diverged > 0 and "DIVERGED" in bare.text
    motion = l6470emu.motion(capture)
    assert motion.divergence is not None and motion.divergence.frame == first.frame
    assert not l6470emu.replay(capture).matched
    # Given the rig's description (a board file, or the description as chain=), it matches.
    rig = tmp_path / "rig.conf"
    rig.write_text(HOMING_RIG + "\n")
    assert l6470emu.replay(capture, board=rig).matched
    assert l6470emu.replay(capture, chain=HOMING_RIG).matched
    assert l6470emu.decode(capture, board=rig).divergence is None
    assert l6470emu.motion(capture, board=str(rig)).divergence is None


def test_a_foreign_capture_the_model_does_not_reproduce_says_where_in_every_result():
    capture = FIXTURES / "ftrace_spi_set_cs.txt"
    d = l6470emu.decode(capture).divergence
    assert d is not None and d.frame == 23 and d.chip == 0
    assert d.what == "MISO byte 0 expected 0xF0, emulated 0xCD"
    assert d.summary.endswith("frame 23 at t=1523.803136 s: chip 0: MISO byte 0 expected 0xF0, emulated 0xCD")
    m = l6470emu.motion(capture)
    assert m.divergence is not None and m.divergence.frame == 23 and m.frames_diverged >= 1
    assert "DIVERGED" in repr(m)
