"""grbl character counting against a grbl SIMULATOR (tests/unit/streamsupport/grbl_sim.py).

The simulator is not a real peer: it models grbl's 127-byte receive buffer (bytes beyond it
are lost and counted), its 16-block planner, "ok"/"error:N" per line and real-time bytes.
"""
from __future__ import annotations

import threading
import time

import pytest

from freecad_conformal.errors import StreamError
from freecad_conformal.stream import Streamer, load_state, program_from_text
from freecad_conformal.stream.grbl import RX_BUFFER_BYTES
from freecad_conformal.stream.program import grbl_line
from tests.unit.streamsupport.grbl_sim import GrblSimulator, parse_error


def make_program(count: int = 1500):
    lines = ["G21 G90 ; mm, absolute"]
    lines += [f"G1 X{i * 0.01:.2f} Y{(i % 13) * 0.7:.1f} F1200 (move {i})" for i in range(1, count)]
    return program_from_text("\n".join(lines) + "\n", "grbl.gcode")


@pytest.fixture
def simulator():
    sim = GrblSimulator()
    yield sim
    sim.close()


def test_simulator_parses_like_grbl():
    assert parse_error("G1X1.5F300") == 0
    assert parse_error("G5X1") == 20
    assert parse_error("X") == 2
    assert parse_error("1X2") == 1
    assert parse_error("G1X" + "1" * 90) == 11


def test_character_counting_fills_but_never_overflows_the_buffer(simulator, tmp_path):
    program = make_program()
    seen = []
    state = Streamer(program, simulator.port, protocol="grbl", state_path=tmp_path / "s.json",
                     on_progress=seen.append, progress_interval=0).run()
    simulator.wait_idle()
    assert state.status == "done" and state.confirmed == len(program)
    assert simulator.executed == [grbl_line(command) for command in program.commands]
    assert simulator.overflowed_bytes == 0
    # Streaming ahead: the buffer held several lines at once (ping-pong would hold one).
    longest = max(len(grbl_line(command)) + 1 for command in program.commands)
    assert longest * 3 < simulator.peak_rx_bytes <= RX_BUFFER_BYTES
    assert seen[-1].confirmed == len(program)


def test_a_larger_assumed_buffer_overflows_the_simulator(simulator):
    """The counting is what keeps bytes from being lost: assume 4x the buffer and they are."""
    from freecad_conformal.stream.grbl import GrblProtocol, GrblTimeouts

    simulator.block_seconds = 0.002  # a slow machine, so the planner backs up
    protocol = GrblProtocol(GrblTimeouts(answer=1.0), rx_buffer_bytes=4 * RX_BUFFER_BYTES)
    with pytest.raises(StreamError):
        Streamer(make_program(400), simulator.port, protocol=protocol).run()
    assert simulator.overflowed_bytes > 0


def test_grbl_error_stops_the_job_naming_the_line(simulator, tmp_path):
    program = program_from_text("G90\nG1 X1 F100\nG5 X2\nG1 X3\n", "bad.gcode")
    with pytest.raises(StreamError, match=r"error 20 .*bad.gcode line 3: 'G5 X2'"):
        Streamer(program, simulator.port, protocol="grbl", state_path=tmp_path / "s.json").run()
    assert load_state(tmp_path / "s.json").status == "failed"


@pytest.mark.slow
def test_pause_holds_the_feed_and_resume_finishes(simulator):
    program = make_program(600)
    simulator.block_seconds = 0.002
    streamer = Streamer(program, simulator.port, protocol="grbl")
    thread = threading.Thread(target=streamer.run)
    thread.start()
    deadline = time.monotonic() + 10
    while streamer.confirmed < 100:
        assert time.monotonic() < deadline
        time.sleep(0.005)
    streamer.pause()
    time.sleep(0.3)
    executed_while_held = len(simulator.executed)
    time.sleep(0.2)
    assert len(simulator.executed) == executed_while_held and simulator.holds == 1
    streamer.resume()
    thread.join(timeout=20)
    simulator.wait_idle()
    assert simulator.executed == [grbl_line(command) for command in program.commands]


def test_resume_with_lines_in_doubt_asks_for_a_line(simulator, tmp_path):
    program = make_program(50)
    state_path = tmp_path / "s.json"
    streamer = Streamer(program, simulator.port, protocol="grbl", state_path=state_path)
    streamer.state.confirmed, streamer.state.sent, streamer.state.status = 10, 14, "disconnected"
    streamer._save()  # as left by a dropped connection with four lines unanswered
    with pytest.raises(StreamError, match=r"lines 11-14 of grbl.gcode were in the controller's buffer"):
        Streamer(program, simulator.port, protocol="grbl", state_path=state_path, resume=True).run()
    Streamer(program, simulator.port, protocol="grbl", state_path=state_path, resume=True,
             from_line=program.source_lines[10]).run()
    simulator.wait_idle()
    assert simulator.executed == [grbl_line(command) for command in program.commands[10:]]
