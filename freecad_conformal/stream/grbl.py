"""grbl/grblHAL protocol: character counting against the controller's serial receive buffer.

grbl answers every line with "ok" or "error:N" once it has parsed it into the planner, and
its serial receive buffer holds 127 bytes (RX_BUFFER_SIZE 128, one slot kept free). The
streamer keeps the lengths of the lines not yet answered and writes the next line only when
it fits, so the buffer never overflows (an overflow loses bytes silently) and never runs dry.

grbl has no line numbers: after a disconnect nothing tells which unanswered lines ran, so a
resume with lines in doubt stops and asks the user for --from-line instead of guessing.
"""
from __future__ import annotations

import collections
import re
import time
from dataclasses import dataclass

from freecad_conformal.errors import StreamError
from freecad_conformal.stream.control import JobControl
from freecad_conformal.stream.port import READ_SLICE, Link
from freecad_conformal.stream.program import grbl_line

#: Usable bytes of grbl's serial receive buffer (RX_BUFFER_SIZE 128 minus the ring's gap).
RX_BUFFER_BYTES = 127
#: grbl's LINE_BUFFER_SIZE is 80 including the NUL: longer lines are rejected (error:11).
MAX_LINE_BYTES = 79
#: Real-time commands: bytes grbl acts on at once, outside the receive buffer.
FEED_HOLD, CYCLE_START, SOFT_RESET, STATUS_QUERY = b"!", b"~", b"\x18", b"?"
#: Seconds between status queries while a controller boots.
STATUS_QUERY_INTERVAL = 0.25
#: Seconds of silence that mark the end of the greeting's stale answers (a grbl answers a
#: line within milliseconds; 0.2 s is ample even at 9600 baud).
GREETING_QUIET = 0.2
#: The meaning of the errors a program (not a setting) can cause, from grbl 1.1's error list.
ERROR_MEANINGS = {
    1: "G-code words consist of a letter and a value; letter was not found",
    2: "numeric value format is not valid or missing an expected value",
    9: "G-code locked out during alarm or jog state",
    11: "max characters per line exceeded",
    15: "jog target exceeds machine travel",
    20: "unsupported or invalid g-code command found in block",
    22: "feed rate has not yet been set or is undefined",
    24: "two G-code commands that both require the use of the XYZ axis words",
    33: "the motion command has an invalid target",
}
ALARM_MEANINGS = {1: "hard limit triggered", 2: "soft limit: target exceeds machine travel",
                  3: "reset while in motion: position lost", 9: "homing failed"}
_ERROR = re.compile(r"^error:\s*(\d+)", re.IGNORECASE)
_ALARM = re.compile(r"^alarm:\s*(\d+)", re.IGNORECASE)


@dataclass(frozen=True)
class GrblTimeouts:
    """Seconds of silence tolerated.

    Attributes:
        answer: grbl answers when a line enters the planner; with the planner full that is
            when the oldest block finishes, so a single long move can hold an answer back.
            Real grbl never drops an answer, so silence this long means a dead link.
        banner: grbl resets when the port opens (DTR) and greets after ~1 s; a controller
            that shows no sign of life for this long is not there.
    """

    answer: float = 600.0
    banner: float = 2.5


def check_line_lengths(job: JobControl) -> None:
    """Refuse commands longer than grbl's line buffer before anything is sent."""
    for index, command in enumerate(job.program.commands):
        line = grbl_line(command)
        if len(line) > MAX_LINE_BYTES:
            raise StreamError(
                f"{job.program.path or '<text>'} line {job.program.source_lines[index]}: "
                f"{len(line)} characters, grbl takes at most {MAX_LINE_BYTES}; shorten the command"
            )


class GrblProtocol:
    """Feeds a grbl or grblHAL controller, keeping its receive buffer full but never over."""

    name = "grbl"

    def __init__(self, timeouts: GrblTimeouts = GrblTimeouts(),
                 rx_buffer_bytes: int = RX_BUFFER_BYTES) -> None:
        self.timeouts = timeouts
        self.rx_buffer_bytes = rx_buffer_bytes

    def check(self, job: JobControl) -> None:
        check_line_lengths(job)

    def run(self, link: Link, job: JobControl) -> None:
        if not job.renumber and job.sent > job.confirmed:
            program = job.program
            first = program.source_lines[job.confirmed]
            last = program.source_lines[job.sent - 1]
            raise StreamError(
                f"lines {first}-{last} of {program.path or '<text>'} were in the controller's "
                "buffer when the connection dropped; grbl has no line numbers to tell whether "
                "they ran: check the part, then resume with --from-line"
            )
        _GrblRun(link, job, self).run()


class _GrblRun:
    def __init__(self, link: Link, job: JobControl, protocol: GrblProtocol) -> None:
        self.link, self.job = link, job
        self.timeouts, self.capacity = protocol.timeouts, protocol.rx_buffer_bytes
        self.total = len(job.program)
        self.lines = [grbl_line(command) + "\n" for command in job.program.commands]
        self.unanswered: collections.deque[tuple[int, int]] = collections.deque()  # (index, bytes)
        self.buffered_bytes = 0
        self.next_index = job.confirmed
        self.held = False
        self.last_traffic = time.monotonic()

    def _fail(self, message: str, index: int) -> None:
        index = min(index, self.total - 1)
        raise StreamError(f"{message} (at {self.job.program.path or '<text>'} line "
                          f"{self.job.program.source_lines[index]}: "
                          f"{self.job.program.commands[index]!r})")

    def _greet(self) -> None:
        """Make sure a live controller listens before the first line, and drop stale answers.

        A newline ends any half line left in grbl's line buffer by an earlier session; the
        status query '?' is acted on at once by a running grbl (it is lost while the board
        reboots after the reset many boards do when the port opens, hence the repeats).
        """
        self.link.write(b"\n")
        deadline = time.monotonic() + self.timeouts.banner
        next_query = 0.0
        while True:
            now = time.monotonic()
            if now >= deadline:
                raise StreamError(f"no grbl answers on {self.link.name} (no banner, no status "
                                  f"report in {self.timeouts.banner:.1f} s): is it a grbl "
                                  "controller, switched on, at this baud rate?")
            if now >= next_query:
                self.link.write(STATUS_QUERY)
                next_query = now + STATUS_QUERY_INTERVAL
            text = self.link.readline(READ_SLICE)
            if text is None:
                continue
            self.job.log("<", text)
            if text.startswith("<") or text.lower().startswith("grbl"):
                break
        # Answers to the newline and to repeated queries are stale: wait for quiet.
        while (text := self.link.readline(GREETING_QUIET)) is not None:
            self.job.log("<", text)

    def _fill_buffer(self) -> None:
        while (self.next_index < self.total and not self.job.paused and not self.job.stopping
               and self.buffered_bytes + len(self.lines[self.next_index]) <= self.capacity):
            line = self.lines[self.next_index]
            self.job.log(">", line.rstrip("\n"))
            self.link.write(line.encode("ascii", errors="replace"))
            self.job.mark_sent(self.next_index)
            self.unanswered.append((self.next_index, len(line)))
            self.buffered_bytes += len(line)
            self.next_index += 1

    def _follow_pause(self) -> None:
        """Hold the feed while paused: grbl decelerates and stops at once, then resumes."""
        if self.job.paused != self.held:
            self.held = self.job.paused
            self.link.write(FEED_HOLD if self.held else CYCLE_START)
            self.job.log(">", "! (feed hold)" if self.held else "~ (cycle start)")

    def _answered(self) -> int:
        index, length = self.unanswered.popleft()
        self.buffered_bytes -= length
        return index

    def _handle(self, text: str) -> None:
        lower = text.lower()
        error, alarm = _ERROR.match(text), _ALARM.match(text)
        if lower == "ok":
            if not self.unanswered:
                self.job.log("#", "ok without a line in flight: ignored")
                return
            self.job.mark_confirmed(self._answered() + 1)
        elif error:
            index = self._answered() if self.unanswered else self.job.confirmed
            code = int(error.group(1))
            self._fail(f"grbl refused a line with error {code} "
                       f"({ERROR_MEANINGS.get(code, 'see grbl error codes')})", index)
        elif alarm:
            code = int(alarm.group(1))
            self._fail(f"grbl raised alarm {code} ({ALARM_MEANINGS.get(code, 'see grbl alarm codes')}); "
                       "clear it ($X or homing) before resuming", self.job.confirmed)
        elif lower.startswith("grbl"):
            self._fail(f"the controller restarted ({text!r}): moves it had queued are lost; "
                       "check the part, then resume with --from-line", self.job.confirmed)

    def run(self) -> None:
        self._greet()
        while True:
            if self.job.stopping and self.job.emergency:
                self.link.write(SOFT_RESET)
                self.job.log(">", "Ctrl-X (soft reset: emergency stop)")
                return
            self._follow_pause()
            self._fill_buffer()
            if self.job.confirmed >= self.total:
                return
            if self.job.stopping and not self.unanswered:
                return
            text = self.link.readline(READ_SLICE)
            now = time.monotonic()
            if text is None:
                if self.unanswered and not self.held and now - self.last_traffic > self.timeouts.answer:
                    self._fail(f"no answer from {self.link.name} for {self.timeouts.answer:.0f} s",
                               self.job.confirmed)
                continue
            self.last_traffic = now
            if text:
                self.job.log("<", text)
                self._handle(text)
