"""Streaming without a machine: program parsing, checksums, state files, port errors."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from freecad_conformal.errors import StreamError
from freecad_conformal.stream import Streamer, load_state, program_from_text
from freecad_conformal.stream.port import SerialLink, import_pyserial
from freecad_conformal.stream.program import grbl_line, load_program, marlin_checksum, marlin_line
from freecad_conformal.stream.state import StreamState, save_state
from tests.conftest import PROJECT_ROOT


def test_program_drops_comments_blank_lines_numbers_and_checksums():
    text = "; header\n\nG90 ; absolute\nN7 G1 X1 (inline) Y2*33\n%\n  M117 hi  \n"
    program = program_from_text(text, "p.gcode")
    assert program.commands == ("G90", "G1 X1  Y2", "M117 hi")
    assert program.source_lines == (3, 4, 6)
    assert program.index_of_file_line(4) == 1
    assert program.index_of_file_line(5) == 2
    with pytest.raises(StreamError, match="line 7"):
        program.index_of_file_line(7)


def test_program_refuses_m110_and_empty_programs(tmp_path):
    with pytest.raises(StreamError, match="line 2.*M110"):
        program_from_text("G1 X1\nM110 N5\n")
    with pytest.raises(StreamError, match="no G-code command"):
        program_from_text("; only a comment\n\n")
    with pytest.raises(StreamError, match="does not exist"):
        load_program(tmp_path / "missing.gcode")
    (tmp_path / "bin.gcode").write_bytes(b"G1 X1\n\xff\xfe\n")
    with pytest.raises(StreamError, match="not UTF-8"):
        load_program(tmp_path / "bin.gcode")


def test_checksum_agrees_with_octoprint_virtual_printer():
    """The peer's own checksum routine judges every line we format."""
    from octoprint.plugins.virtual_printer.virtual import VirtualPrinter

    commands = ["G1 X10.5 Y-3 F3000", "M104 S210", "G28", "M117 Hello world *!", "T0"]
    for number, command in enumerate(commands * 40):
        line = marlin_line(number, command)
        payload, checksum = line.rsplit("*", 1)
        assert int(checksum) == VirtualPrinter._calculate_checksum(None, payload.encode())
    assert marlin_checksum("N0 M110 N0") == 125  # accepted by the printer in the handshake


def test_grbl_line_is_compact_upper_case():
    assert grbl_line("g1 x1.5  y2 f600") == "G1X1.5Y2F600"


def test_state_round_trip_and_rejections(tmp_path):
    path = tmp_path / "job.json"
    state = StreamState("p.gcode", "ab" * 32, "marlin", 10, confirmed=4, sent=5, status="disconnected")
    save_state(path, state)
    loaded = load_state(path)
    assert (loaded.confirmed, loaded.sent, loaded.status, loaded.total) == (4, 5, "disconnected", 10)
    record = json.loads(path.read_text())
    record["confirmed"] = 7
    path.write_text(json.dumps(record))
    with pytest.raises(StreamError, match="inconsistent"):
        load_state(path)
    path.write_text("{}")
    with pytest.raises(StreamError, match="not a stream state"):
        load_state(path)
    with pytest.raises(StreamError, match="does not exist"):
        load_state(tmp_path / "none.json")


def test_resume_refuses_another_program(tmp_path):
    path = tmp_path / "job.json"
    first = program_from_text("G1 X1\nG1 X2\n", "a.gcode")
    save_state(path, StreamState("a.gcode", first.sha256, "marlin", 2, confirmed=1, sent=1))
    changed = program_from_text("G1 X1\nG1 X3\n", "a.gcode")
    with pytest.raises(StreamError, match="another version of the program"):
        Streamer(changed, "/dev/null", state_path=path, resume=True)
    with pytest.raises(StreamError, match="saved for protocol 'marlin'"):
        Streamer(first, "/dev/null", protocol="grbl", state_path=path, resume=True)


def test_missing_pyserial_names_the_package(monkeypatch):
    monkeypatch.setitem(sys.modules, "serial", None)  # makes `import serial` fail
    with pytest.raises(StreamError, match=r"pyserial.*pip install pyserial"):
        import_pyserial()


def test_missing_port_is_a_clear_error_and_the_state_is_saved(tmp_path):
    program = program_from_text("G1 X1\n", "p.gcode")
    state_path = tmp_path / "job.json"
    with pytest.raises(StreamError, match="/dev/ttyNOPE0 does not exist"):
        Streamer(program, "/dev/ttyNOPE0", state_path=state_path).run()
    saved = load_state(state_path)
    assert saved.status == "failed" and "does not exist" in saved.message


def test_port_without_permission_is_a_clear_error():
    """A real pty whose mode forbids the user; root bypasses modes, so run as 'nobody' then."""
    master, slave = os.openpty()
    folder = Path(tempfile.mkdtemp(prefix="conformal-stream-"))  # reachable by 'nobody'
    try:
        port = os.ttyname(slave)
        os.chmod(port, 0o600)
        folder.chmod(0o777)
        program_path = folder / "p.gcode"
        program_path.write_text("G1 X1\n")
        command = [sys.executable, "-m", "freecad_conformal", "stream", str(program_path),
                   "--port", port, "--quiet"]
        if os.geteuid() == 0:
            result = subprocess.run(command, user="nobody", capture_output=True, text=True,
                                    cwd=PROJECT_ROOT, timeout=60)
        else:
            os.chmod(port, 0o000)
            result = subprocess.run(command, capture_output=True, text=True, cwd=PROJECT_ROOT, timeout=60)
        assert result.returncode == 1, result.stderr
        assert f"no permission to open serial port {port}" in result.stderr
        assert "dialout" in result.stderr
        assert load_state(f"{program_path}.stream.json").status == "failed"
    finally:
        os.close(master)
        os.close(slave)
        shutil.rmtree(folder, ignore_errors=True)


def test_serial_link_reports_a_vanished_device():
    master, slave = os.openpty()
    port = os.ttyname(slave)
    link = SerialLink(port)
    os.close(master)
    os.close(slave)
    with pytest.raises(StreamError, match=f"connection to {port} lost"):
        for _ in range(3):
            link.write(b"G1 X1\n")
            link.readline(0.2)
    link.close()


def test_semicolon_inside_a_parenthesis_comment_is_part_of_the_comment():
    from freecad_conformal.stream.program import clean_command
    assert clean_command("(tolerance: 0.01 mm, 0.05 deg; 3 segments)") == ""
    assert clean_command("G1 X1 (a; b) Y2 ; c (d") == "G1 X1  Y2"
    assert clean_command("G1 X1 ; note (with) parentheses") == "G1 X1"


def test_posted_grblhal_program_is_accepted_line_by_line_by_the_grbl_simulator():
    from freecad_conformal.post import samples
    from freecad_conformal.post.machine import load_machine
    from freecad_conformal.post.program import post_toolpath
    from freecad_conformal.stream.program import grbl_line
    from tests.unit.streamsupport.grbl_sim import parse_error
    text = post_toolpath(samples.tilted_ring(), load_machine("head_a_table_c")).text
    program = program_from_text(text)
    errors = [(line, command) for line, command in zip(program.source_lines, program.commands)
              if parse_error(grbl_line(command), grblhal=True)]
    assert errors == []
