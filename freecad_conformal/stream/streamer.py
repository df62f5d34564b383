"""The streaming job: a program, a port, a wire protocol, progress, a log and a state file.

Usable from the CLI and from a GUI: `run()` blocks in the calling (worker) thread;
`pause()`, `resume()` and `abort()` may be called from any other thread; `on_progress` is
called from the worker thread (a GUI hands it over to its own thread).

The state file is saved when the job starts, at most every `save_interval` seconds while
it runs, on pause, and on every way out (done, abort, error, lost port, Ctrl-C), so a
resume knows which lines the machine acknowledged.
"""
from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass
from typing import IO, Callable

from freecad_conformal.errors import StreamError
from freecad_conformal.stream import grbl, marlin
from freecad_conformal.stream.control import WireProtocol
from freecad_conformal.stream.port import Link, PortLost, SerialLink
from freecad_conformal.stream.program import Program
from freecad_conformal.stream.state import StreamState, load_state, save_state

#: Seconds between state saves while running: each save is an fsync'd atomic write (~1 ms),
#: and after a host crash Marlin's line numbers settle the lines acknowledged since.
DEFAULT_SAVE_INTERVAL = 0.5


@dataclass(frozen=True)
class StreamProgress:
    """A snapshot for progress displays.

    Attributes:
        confirmed: commands acknowledged by the machine.
        total: commands in the program.
        file_line: file line of the next command to confirm (last line when done).
        status: "running", "paused", "aborted", "disconnected", "failed" or "done".
        elapsed: seconds since this run started, pauses excluded.
        eta: estimated seconds left at this run's rate, None before the first confirmation.
    """

    confirmed: int
    total: int
    file_line: int
    status: str
    elapsed: float
    eta: float | None

    @property
    def percent(self) -> float:
        return 100.0 * self.confirmed / self.total if self.total else 100.0


def make_protocol(name: str) -> WireProtocol:
    """The protocol called `name` ("marlin" or "grbl")."""
    protocols: dict[str, Callable[[], WireProtocol]] = {"marlin": marlin.MarlinProtocol,
                                                        "grbl": grbl.GrblProtocol}
    if name not in protocols:
        raise StreamError(f"unknown protocol {name!r}: choose one of {sorted(protocols)}")
    return protocols[name]()


class Streamer:
    """Send one program to one machine, resumably.

    Args:
        program: the program to send.
        port: serial port path (e.g. /dev/ttyUSB0).
        protocol: "marlin", "grbl" or a WireProtocol instance.
        baud: serial speed.
        state_path: where the job's state is saved (required to resume later).
        log_path: a traffic log, appended to (None: no log).
        resume: continue the job saved in `state_path` instead of starting anew.
        from_line: start (or restart) at the first command at or after this file line.
        on_progress: called with a StreamProgress at most every `progress_interval` s.
        link_factory: opens the port (default pyserial); tests may pass another transport.
    """

    def __init__(self, program: Program, port: str, *, protocol: str | WireProtocol = "marlin",
                 baud: int = 115200, state_path: str | os.PathLike | None = None,
                 log_path: str | os.PathLike | None = None, resume: bool = False,
                 from_line: int | None = None,
                 on_progress: Callable[[StreamProgress], None] | None = None,
                 progress_interval: float = 0.1, save_interval: float = DEFAULT_SAVE_INTERVAL,
                 link_factory: Callable[[str, int], Link] = SerialLink) -> None:
        self.program = program
        self.port, self.baud = port, baud
        self.protocol = make_protocol(protocol) if isinstance(protocol, str) else protocol
        self.state_path, self.log_path = state_path, log_path
        self.on_progress, self.progress_interval = on_progress, progress_interval
        self.save_interval = save_interval
        self.link_factory = link_factory
        self.state = self._initial_state(resume, from_line)
        self.renumber = not resume or from_line is not None
        self._pause_requested = threading.Event()
        self._abort_requested = threading.Event()
        self._emergency = False
        self._was_paused = False
        self._log: IO[str] | None = None
        self._start = self._last_save = self._last_progress = time.monotonic()
        self._paused_since: float | None = None
        self._paused_total = 0.0
        self._confirmed_at_start = self.state.confirmed

    def _initial_state(self, resume: bool, from_line: int | None) -> StreamState:
        if resume:
            if self.state_path is None:
                raise StreamError("resuming needs the state file of the interrupted job")
            state = load_state(self.state_path)
            if state.program_sha256 != self.program.sha256:
                raise StreamError(f"stream state {self.state_path} belongs to another version of the "
                                  f"program (saved for {state.program}); refusing to resume")
            if state.protocol != self.protocol.name:
                raise StreamError(f"stream state {self.state_path} was saved for protocol "
                                  f"{state.protocol!r}, not {self.protocol.name!r}")
        else:
            state = StreamState(self.program.path, self.program.sha256, self.protocol.name,
                                len(self.program))
        if from_line is not None:
            state.confirmed = state.sent = self.program.index_of_file_line(from_line)
        state.port, state.status, state.message = self.port, "running", ""
        return state

    # -- control from any thread --------------------------------------------------------
    def pause(self) -> None:
        """Stop sending new lines (grbl also holds its feed) until resume()."""
        self._pause_requested.set()

    def resume(self) -> None:
        self._pause_requested.clear()

    def abort(self, emergency: bool = False) -> None:
        """Stop the job; with `emergency`, halt the machine at once (M112 / grbl soft reset)."""
        self._emergency = emergency
        self._abort_requested.set()

    # -- JobControl, called by the protocol in the worker thread -------------------------
    @property
    def confirmed(self) -> int:
        return self.state.confirmed

    @property
    def sent(self) -> int:
        return self.state.sent

    @property
    def paused(self) -> bool:
        """Whether to hold; the worker thread asks, so it also records each change of status
        (pause time excluded from the rate, state saved, progress reported)."""
        paused = self._pause_requested.is_set() and not self._abort_requested.is_set()
        if paused != self._was_paused:
            self._was_paused = paused
            now = time.monotonic()
            if paused:
                self._paused_since = now
            else:
                self._paused_total += now - (self._paused_since or now)
                self._paused_since = None
            self.state.status = "paused" if paused else "running"
            self._save()
            self._report(force=True)
        return paused

    @property
    def stopping(self) -> bool:
        return self._abort_requested.is_set()

    @property
    def emergency(self) -> bool:
        return self._emergency

    def mark_sent(self, index: int) -> None:
        self.state.sent = max(self.state.sent, index + 1)

    def mark_confirmed(self, count: int) -> None:
        if count <= self.state.confirmed:
            return
        self.state.confirmed = count
        self.state.sent = max(self.state.sent, count)
        now = time.monotonic()
        if now - self._last_save >= self.save_interval:
            self._save()
        self._report()

    def withdraw_confirmation(self, count: int) -> None:
        if count >= self.state.confirmed:
            return
        self.state.confirmed = count
        self._save()
        self._report()

    def log(self, direction: str, text: str) -> None:
        if self._log is not None:
            self._log.write(f"{time.monotonic() - self._start:10.3f} {direction} {text}\n")

    # -- running ---------------------------------------------------------------------------
    def _save(self) -> None:
        self._last_save = time.monotonic()
        if self.state_path is not None:
            save_state(self.state_path, self.state)

    def progress(self) -> StreamProgress:
        now = time.monotonic()
        paused = self._paused_total + (now - self._paused_since if self._paused_since else 0.0)
        elapsed = now - self._start - paused
        done_here = self.state.confirmed - self._confirmed_at_start
        remaining = self.state.total - self.state.confirmed
        eta = remaining * elapsed / done_here if done_here > 0 else None
        index = min(self.state.confirmed, self.state.total - 1)
        return StreamProgress(self.state.confirmed, self.state.total,
                              self.program.source_lines[index], self.state.status, elapsed, eta)

    def _report(self, force: bool = False) -> None:
        now = time.monotonic()
        if self.on_progress is not None and (force or now - self._last_progress >= self.progress_interval):
            self._last_progress = now
            self.on_progress(self.progress())

    def _finish(self, status: str, message: str = "") -> None:
        self.state.status, self.state.message = status, message
        self.log("#", f"job {status}{': ' + message if message else ''} "
                      f"({self.state.confirmed}/{self.state.total} confirmed)")
        self._save()
        self._report(force=True)

    def run(self) -> StreamState:
        """Stream until done or aborted; returns the final state.

        Raises:
            StreamError: the port cannot be opened, the machine reports an error, stops
                answering, or disconnects (PortLost). The state is saved first.
        """
        self.protocol.check(self)
        self._start = time.monotonic()
        # The log is appended live (not written atomically): after a crash, the traffic up
        # to the crash is exactly what one wants to read.
        self._log = open(self.log_path, "a", encoding="utf-8") if self.log_path else None
        link: Link | None = None
        try:
            self._save()
            self.log("#", f"job start: {self.program.path} on {self.port} ({self.protocol.name}), "
                          f"command {self.state.confirmed + 1} of {self.state.total}")
            link = self.link_factory(self.port, self.baud)
            self.protocol.run(link, self)
        except PortLost as exc:
            self._finish("disconnected", str(exc))
            raise
        except StreamError as exc:
            self._finish("failed", str(exc))
            raise
        except KeyboardInterrupt:
            self._finish("aborted", "interrupted")
            raise
        else:
            done = self.state.confirmed >= self.state.total
            self._finish("done" if done else "aborted",
                         "" if done else "aborted by the user")
        finally:
            if link is not None:
                link.close()
            if self._log is not None:
                self._log.close()
                self._log = None
        return self.state
