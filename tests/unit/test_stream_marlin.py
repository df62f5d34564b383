"""Marlin streaming against a real peer: OctoPrint's virtual printer on a pseudo-terminal.

Every test counts what the printer dispatched (RecordingPrinter.executed) and compares it
with the program: each command exactly once, in order.
"""
from __future__ import annotations

import threading
import time

import pytest

from freecad_conformal.cli import main
from freecad_conformal.errors import StreamError
from freecad_conformal.stream import PortLost, Streamer, load_state, program_from_text
from freecad_conformal.stream.marlin import MarlinProtocol, MarlinTimeouts
from tests.unit.streamsupport.virtual_printer import Faults, PtyPrinter


def make_program(count: int = 400):
    """Distinct commands, so a repeated or skipped one cannot hide in the count."""
    lines = ["; generated test program", "G90", "M117 start"]
    lines += [f"G1 X{i * 0.1:.1f} Y{(i % 17) * 0.3:.1f} F60000 ; move {i}" for i in range(1, count)]
    lines += ["M117 end"]
    return program_from_text("\n".join(lines) + "\n", "generated.gcode")


@pytest.fixture
def printer_factory():
    printers = []

    def make(**kwargs) -> PtyPrinter:
        printers.append(PtyPrinter(**kwargs))
        return printers[-1]

    yield make
    for printer in printers:
        printer.close()


def test_program_streams_end_to_end_with_progress_and_log(printer_factory, tmp_path):
    program = make_program()
    printer = printer_factory()
    seen = []
    streamer = Streamer(program, printer.port, state_path=tmp_path / "s.json",
                        log_path=tmp_path / "s.log", on_progress=seen.append, progress_interval=0)
    state = streamer.run()
    assert printer.executed == list(program.commands)
    assert state.status == "done" and state.confirmed == state.sent == len(program)
    assert load_state(tmp_path / "s.json").status == "done"
    counts = [progress.confirmed for progress in seen]
    assert counts == sorted(counts) and counts[-1] == len(program)
    assert seen[-1].percent == 100.0 and seen[-1].eta == 0.0
    log = (tmp_path / "s.log").read_text()
    assert "> N0 M110 N0*125" in log and f"> N{len(program)} M117 end*" in log


def test_corrupted_lines_and_resend_requests_run_each_line_once(printer_factory, tmp_path):
    program = make_program()
    faults = Faults(corrupt={20, 21, 300}, drop_ok={60})
    # The printer's own simulated errors add resend requests of its making.
    printer = printer_factory(faults=faults, simulated_errors=["100:resend", "115:checksum_mismatch"])
    state = Streamer(program, printer.port, log_path=tmp_path / "s.log").run()
    assert printer.executed == list(program.commands)
    assert state.status == "done"
    log = (tmp_path / "s.log").read_text()
    assert log.count("< Resend:") >= 6  # 3 corrupted, 2 simulated, 1 after the lost ok
    assert "printer idle ('wait') with a line unanswered: repeating line 60" in log


def test_lost_ok_without_wait_messages_recovers_by_timeout(printer_factory, tmp_path):
    program = make_program(120)
    printer = printer_factory(faults=Faults(drop_ok={30, 31}), sendWait=False)
    protocol = MarlinProtocol(MarlinTimeouts(answer=0.4))
    Streamer(program, printer.port, protocol=protocol, log_path=tmp_path / "s.log").run()
    assert printer.executed == list(program.commands)
    assert (tmp_path / "s.log").read_text().count("no answer for") >= 2  # one per lost ok


@pytest.mark.parametrize("where", ["after", "before"])
def test_disconnect_mid_program_resumes_without_loss_or_repeat(printer_factory, tmp_path, where):
    """The cable drops with line 150 executed-but-unacknowledged (or not yet delivered)."""
    program = make_program()
    faults = Faults(**{f"disconnect_{where}": {150}})
    printer = printer_factory(faults=faults)
    state_path = tmp_path / "s.json"
    with pytest.raises(PortLost, match="lost"):
        Streamer(program, printer.port, state_path=state_path).run()
    saved = load_state(state_path)
    assert (saved.status, saved.confirmed, saved.sent) == ("disconnected", 149, 150)
    assert len(printer.executed) == (150 if where == "after" else 149)
    printer.connect()  # plugged back in: a new port path, the same firmware
    state = Streamer(program, printer.port, state_path=state_path, resume=True).run()
    assert state.status == "done"
    assert printer.executed == list(program.commands)


def test_restarted_firmware_is_detected_and_from_line_restarts(printer_factory, tmp_path):
    program = make_program(200)
    state_path = tmp_path / "s.json"
    first = printer_factory(faults=Faults(disconnect_after={90}))
    with pytest.raises(PortLost):
        Streamer(program, first.port, state_path=state_path).run()
    rebooted = printer_factory()  # a fresh firmware: it lost its line count and its queue
    with pytest.raises(StreamError, match="lost its place"):
        Streamer(program, rebooted.port, state_path=state_path, resume=True).run()
    assert load_state(state_path).status == "failed"
    assert rebooted.executed == []
    from_line = program.source_lines[89]  # the user restarts at command 90 after checking
    Streamer(program, rebooted.port, state_path=state_path, resume=True, from_line=from_line).run()
    assert rebooted.executed == list(program.commands[89:])


def run_in_thread(streamer: Streamer) -> tuple[threading.Thread, dict]:
    outcome: dict = {}

    def work() -> None:
        try:
            outcome["state"] = streamer.run()
        except StreamError as exc:
            outcome["error"] = exc

    thread = threading.Thread(target=work)
    thread.start()
    return thread, outcome


def wait_for(condition, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "condition not reached in time"
        time.sleep(0.005)


def test_pause_resume_and_abort_from_another_thread(printer_factory, tmp_path):
    program = make_program()
    printer = printer_factory()
    state_path = tmp_path / "s.json"
    streamer = Streamer(program, printer.port, state_path=state_path)
    thread, outcome = run_in_thread(streamer)
    wait_for(lambda: streamer.confirmed >= 100)
    streamer.pause()
    wait_for(lambda: load_state(state_path).status == "paused")
    held = streamer.confirmed
    time.sleep(0.3)
    assert streamer.confirmed == held and len(printer.executed) == held
    streamer.resume()
    wait_for(lambda: streamer.confirmed >= 250)
    streamer.abort()
    thread.join(timeout=10)
    state = outcome["state"]
    assert state.status == "aborted" and 250 <= state.confirmed < len(program)
    assert printer.executed == list(program.commands[:state.confirmed])
    resumed = Streamer(program, printer.port, state_path=state_path, resume=True).run()
    assert resumed.status == "done"
    assert printer.executed == list(program.commands)


def test_emergency_abort_sends_m112(printer_factory):
    printer = printer_factory()
    streamer = Streamer(make_program(), printer.port)
    thread, outcome = run_in_thread(streamer)
    wait_for(lambda: streamer.confirmed >= 50)
    streamer.abort(emergency=True)
    thread.join(timeout=10)
    assert outcome["state"].status == "aborted"
    wait_for(lambda: printer.printer._killed, timeout=2)


@pytest.mark.slow
def test_temperature_wait_and_busy_keep_the_line_alive(printer_factory, tmp_path):
    """M109 keeps the printer silent but for temperature reports and "busy:" for ~2 s,
    longer than both timeouts here: that traffic must stop the streamer from repeating."""
    program = program_from_text("M104 S40\nG1 X1 F6000\nM109 S40\nG4 P100\nG1 X2\nM117 hot\n", "t.gcode")
    printer = printer_factory(sendBusy=True, busyInterval=0.5)
    protocol = MarlinProtocol(MarlinTimeouts(answer=1.2, long_command=1.2))
    started = time.monotonic()
    Streamer(program, printer.port, protocol=protocol, log_path=tmp_path / "s.log").run()
    assert time.monotonic() - started > 1.2  # the wait really outlasted the timeouts
    assert printer.executed == list(program.commands)
    log = (tmp_path / "s.log").read_text()
    assert "busy" in log and "< T:" in log
    assert "repeating line" not in log


@pytest.mark.slow
def test_cli_streams_and_resumes_after_a_disconnect(printer_factory, tmp_path, capsys):
    program_path = tmp_path / "job.gcode"
    program_path.write_text("\n".join(f"G1 X{i}.5 F60000" for i in range(300)) + "\n")
    printer = printer_factory(faults=Faults(disconnect_after={120}))
    state_path, log_path = tmp_path / "job.state.json", tmp_path / "job.log"
    args = ["stream", str(program_path), "--port", printer.port, "--state", str(state_path),
            "--log", str(log_path), "--quiet"]
    assert main(args) == 1
    assert "error: connection to" in capsys.readouterr().err
    printer.connect()
    assert main(["stream", str(program_path), "--port", printer.port, "--resume",
                 str(state_path), "--log", str(log_path), "--quiet"]) == 0
    assert "done: 300 of 300 commands acknowledged" in capsys.readouterr().out
    assert printer.executed == [f"G1 X{i}.5 F60000" for i in range(300)]


def test_duplicated_ok_does_not_put_the_sender_a_line_ahead(printer_factory, tmp_path):
    # one answer arrives twice; a later corrupted line makes the printer ask for a line
    # the sender had counted as acknowledged on the strength of the extra "ok"
    program = make_program(200)
    printer = printer_factory(faults=Faults(duplicate_ok={50, 120}, corrupt={52, 121}))
    state = Streamer(program, printer.port, log_path=tmp_path / "s.log",
                     state_path=tmp_path / "s.json").run()
    assert printer.executed == list(program.commands)
    assert state.status == "done" and state.confirmed == len(program)
