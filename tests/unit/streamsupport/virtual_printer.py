"""OctoPrint's virtual printer behind a real pseudo-terminal, with optional fault injection.

OctoPrint's VirtualPrinter (octoprint.plugins.virtual_printer.virtual) is a file-like object
(readline/write), not a tty. PtyPrinter bridges it to a pseudo-terminal with two threads, so
the streamer opens a real serial port path through pyserial. The printer's own code decides
what runs; the subclass below only records each command it dispatches, in order.

Faults (by Marlin line number N, each applied to the first transmission only):
    corrupt: flip one byte of the line on its way to the printer (its checksum then fails).
    drop_ok: swallow the "ok" that answers the line.
    disconnect_after: let the line reach the printer, swallow its "ok", and hang up.
    disconnect_before: hang up instead of delivering the line.
    duplicate_ok: send the "ok" that answers the line twice.
"""
from __future__ import annotations

import atexit
import contextlib
import os
import re
import select
import shutil
import tempfile
import threading
import time
import tty
from dataclasses import dataclass, field

_LINE_NUMBER = re.compile(rb"^N(\d+)\s")
_octoprint_lock = threading.Lock()
_octoprint_ready = False


def _init_octoprint() -> None:
    """OctoPrint's settings and plugin manager are process-wide singletons: set them up once."""
    global _octoprint_ready
    with _octoprint_lock:
        if _octoprint_ready:
            return
        import octoprint.plugin
        import octoprint.settings

        basedir = tempfile.mkdtemp(prefix="conformal-octoprint-")
        atexit.register(shutil.rmtree, basedir, True)
        octoprint.settings.settings(init=True, basedir=basedir)
        octoprint.plugin.plugin_manager(init=True, plugin_folders=[], plugin_entry_points=[],
                                        plugin_disabled_list=[])
        _octoprint_ready = True


def make_virtual_printer(**overrides):
    """A RecordingPrinter with the plugin's default settings, changed by `overrides`.

    The printer's built-in simulated errors are off unless asked for: tests choose faults.
    """
    _init_octoprint()
    import octoprint.plugin
    import octoprint.settings
    from octoprint.plugins.virtual_printer import VirtualPrinterPlugin
    from octoprint.plugins.virtual_printer.virtual import VirtualPrinter

    class RecordingPrinter(VirtualPrinter):
        """The virtual printer, recording every command it dispatches (N and checksum removed)."""

        # OctoPrint's printer answers a checksum error with "Resend: current_line + 1", where
        # current_line counts every checksummed line received, repeats included; after the
        # first resend it runs ahead of the line number and the printer would ask for lines
        # never sent (and set its line count past them). Marlin asks for its last N + 1:
        # tying the counter to lastN makes the peer do what Marlin does.
        current_line = property(lambda self: self.lastN, lambda self, value: None)

        def __init__(self, *args, **kwargs) -> None:
            self.executed: list[str] = []
            super().__init__(*args, **kwargs)

        def _record(self, data: str) -> None:
            self.executed.append(data.strip())

        def _gcode_G(self, code: str, data: str) -> bool:
            self._record(data)
            return False  # not handled here: the printer's own G handler runs next

        def _gcode_M(self, code: str, data: str) -> bool:
            self._record(data)
            return False

    defaults = VirtualPrinterPlugin().get_settings_defaults()
    defaults.update({"simulated_errors": [], **overrides})
    plugin_settings = octoprint.plugin.PluginSettings(octoprint.settings.settings(),
                                                      "virtual_printer", defaults=defaults)
    data_folder = tempfile.mkdtemp(prefix="conformal-vp-")
    atexit.register(shutil.rmtree, data_folder, True)
    return RecordingPrinter(plugin_settings, None, data_folder=data_folder, read_timeout=0.05)


@dataclass
class Faults:
    corrupt: set[int] = field(default_factory=set)
    drop_ok: set[int] = field(default_factory=set)
    disconnect_after: set[int] = field(default_factory=set)
    disconnect_before: set[int] = field(default_factory=set)
    duplicate_ok: set[int] = field(default_factory=set)


class PtyPrinter:
    """A virtual printer on a pseudo-terminal; `port` is the path to open. Reconnectable."""

    def __init__(self, printer=None, faults: Faults | None = None, **settings) -> None:
        self.printer = printer if printer is not None else make_virtual_printer(**settings)
        self.faults = faults or Faults()
        self._seen: set[int] = set()
        self._drop_next_ok = False
        self._duplicate_next_ok = False
        self._hang_up_at_next_ok = False
        self._closed = threading.Event()
        self._lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        self.connect()

    @property
    def executed(self) -> list[str]:
        return self.printer.executed

    def connect(self) -> None:
        """Open a fresh pseudo-terminal to the same printer (a cable plugged back in)."""
        master, slave = os.openpty()
        tty.setraw(slave)  # no echo, no newline translation: a plain byte pipe
        with self._lock:
            self._master, self._slave = master, slave
            self.port = os.ttyname(slave)
            self._closed = closed = threading.Event()
        # Each connection's threads hold their own fd and event, so threads of a dropped
        # connection can never read from the next one.
        threads = [threading.Thread(target=self._to_printer, args=(master, closed), daemon=True),
                   threading.Thread(target=self._from_printer, args=(master, closed), daemon=True)]
        self._threads += threads
        for thread in threads:
            thread.start()

    def hang_up(self) -> None:
        """Drop the connection: the streamer's port reports the device gone."""
        with self._lock:
            if self._closed.is_set():
                return
            self._closed.set()
            for fd in (self._master, self._slave):
                with contextlib.suppress(OSError):
                    os.close(fd)

    def close(self) -> None:
        self.hang_up()
        for thread in self._threads:
            thread.join(timeout=2)
        # Let the printer finish its queued moves: closing mid-move makes its buffer thread
        # fail on the queue that close() removes.
        deadline = time.monotonic() + 2
        while self.printer.buffered is not None and self.printer.buffered.unfinished_tasks:
            if time.monotonic() > deadline:
                break
            time.sleep(0.01)
        self.printer.close()

    def _to_printer(self, master: int, closed: threading.Event) -> None:
        pending = b""
        while not closed.is_set():
            try:
                ready, _, _ = select.select([master], [], [], 0.05)
                chunk = os.read(master, 4096) if ready else b""
            except OSError:
                return  # hung up, or the streamer closed its end
            pending += chunk
            while b"\n" in pending:
                line, pending = pending.split(b"\n", 1)
                if not self._deliver(line + b"\n"):
                    return

    def _deliver(self, line: bytes) -> bool:
        match = _LINE_NUMBER.match(line)
        number = int(match.group(1)) if match else None
        first_time = number is not None and number not in self._seen
        if first_time:
            self._seen.add(number)
            if number in self.faults.disconnect_before:
                self.hang_up()
                return False
            if number in self.faults.corrupt:
                position = line.index(b" ") + 1  # a byte of the command itself
                line = line[:position] + bytes([line[position] ^ 0x20]) + line[position + 1:]
            if number in self.faults.drop_ok:
                self._drop_next_ok = True
            if number in self.faults.duplicate_ok:
                self._duplicate_next_ok = True
            if number in self.faults.disconnect_after:
                self._hang_up_at_next_ok = True
        self.printer.write(line)
        return True

    def _from_printer(self, master: int, closed: threading.Event) -> None:
        while not closed.is_set():
            line = self.printer.readline()
            if not line:
                continue
            if line.strip().startswith(b"ok"):
                if self._hang_up_at_next_ok:
                    self._hang_up_at_next_ok = False
                    self.hang_up()
                    return
                if self._drop_next_ok:
                    self._drop_next_ok = False
                    continue
                if self._duplicate_next_ok:      # line noise that repeats a whole answer
                    self._duplicate_next_ok = False
                    line = line.rstrip(b"\n") + b"\n"
                    line = line + line
            try:
                os.write(master, line if line.endswith(b"\n") else line + b"\n")
            except OSError:
                return
