"""Marlin/RepRap protocol: line numbers, checksums, one line in flight, "Resend: N" recovery.

Why every command executes exactly once: each line goes out as `N<n> <cmd>*<checksum>`, and
the firmware runs a line only when its checksum is right and n is its last line number + 1.
So a repeated line is refused, a corrupted one is refused, and no line can be skipped. The
host only has to keep asking for the line the firmware wants:

* "ok" answers the oldest line in flight (one line is in flight at a time: ping-pong, as
  OctoPrint and Printrun do, because a plain "ok" does not say which line it answers).
* "Resend: r" means lines below r ran; the next "ok" belongs to the refused line, then
  line r goes out again.
* A lost "ok" (noise, a dropped byte) is noticed when the printer says "wait" (it is idle
  with nothing to do) or after a timeout without any traffic; the line in flight is then
  repeated with the same number, and the firmware either runs it or answers "Resend: n+1".
* "busy:" (host keep-alive) and temperature reports during M109/M190 count as traffic, so
  long waits never time out while the firmware is alive.

On resume after a disconnect the saved line in flight is sent again with its own number:
if the firmware kept its state, its answer tells whether the line ran; if it restarted, it
asks for a line below the saved position and the job stops with advice (--from-line).
"""
from __future__ import annotations

import collections
import re
import time
from dataclasses import dataclass

from freecad_conformal.errors import StreamError
from freecad_conformal.stream.control import JobControl
from freecad_conformal.stream.port import READ_SLICE, Link
from freecad_conformal.stream.program import marlin_line

#: Marlin's MAX_CMD_SIZE is 96 bytes including the terminating NUL: longer lines are cut.
MAX_LINE_BYTES = 95
#: Commands that legitimately keep the firmware silent for long (homing, probing, heating,
#: dwell, draining the planner, filament change, user pause) on firmware without keep-alive.
LONG_COMMANDS = frozenset({"G4", "G28", "G29", "G30", "G33", "M0", "M1", "M109", "M190",
                           "M191", "M303", "M400", "M600"})
#: Error texts after which Marlin halts (it will not take more commands until reset).
FATAL_ERROR_WORDS = ("halted", "kill", "maxtemp", "mintemp", "thermal runaway",
                     "heating failed", "emergency", "stopped")
#: How many lines an extra "ok" may have put the count ahead of the firmware before a
#: request for an earlier line means the machine lost its place (it restarted). Each
#: repeated answer adds one; a restarted Marlin asks for line 1, which never qualifies.
MAX_EXTRA_OKS = 8
_RESEND = re.compile(r"^(?:resend|rs)[:\s]\s*N?(\d+)", re.IGNORECASE)
_CODE = re.compile(r"^([GMT])0*(\d+)", re.IGNORECASE)


@dataclass(frozen=True)
class MarlinTimeouts:
    """Seconds of silence after which an answer is presumed lost.

    Attributes:
        answer: for ordinary commands. Marlin answers a move once it is queued; with host
            keep-alive (default since Marlin 2.0) a busy firmware says "busy:" every 2 s, so
            10 s of silence means the "ok" was lost rather than the machine busy.
        long_command: for LONG_COMMANDS on firmware without keep-alive (homing a big
            machine or heating a bed can take minutes without a word).
        handshake: between attempts at the first M110 while the board boots (a reset on
            connect keeps Marlin deaf for about 2 s).
        wait_grace: a "wait" only means the printer saw no line if the line in flight was
            sent at least this long before (it is sent when idle for 1 s, so a line written
            just before it may not have arrived yet).
        attempts: resends of one line after silence before the job fails as unanswered.
    """

    answer: float = 10.0
    long_command: float = 600.0
    handshake: float = 2.0
    wait_grace: float = 0.5
    attempts: int = 5


def command_code(command: str) -> str:
    """'G1', 'M109', ... of a command (leading zeros dropped), '' when it has none."""
    match = _CODE.match(command)
    return f"{match.group(1).upper()}{int(match.group(2))}" if match else ""


def check_line_lengths(job: JobControl) -> None:
    """Refuse commands longer than Marlin's buffer before anything is sent."""
    for index, command in enumerate(job.program.commands):
        line = marlin_line(index + 1, command)
        if len(line) > MAX_LINE_BYTES:
            raise StreamError(
                f"{job.program.path or '<text>'} line {job.program.source_lines[index]}: "
                f"{len(line)} bytes with line number and checksum, Marlin takes at most "
                f"{MAX_LINE_BYTES}; shorten the command"
            )


class MarlinProtocol:
    """Feeds a Marlin (or RepRap-style) firmware one checked, numbered line at a time."""

    name = "marlin"

    def __init__(self, timeouts: MarlinTimeouts = MarlinTimeouts()) -> None:
        self.timeouts = timeouts

    def check(self, job: JobControl) -> None:
        check_line_lengths(job)

    def run(self, link: Link, job: JobControl) -> None:
        _MarlinRun(link, job, self.timeouts).run()

    @staticmethod
    def emergency_stop(link: Link) -> None:
        """M112 without line number: Marlin's emergency parser acts on it at once."""
        link.write(b"M112\n")


class _MarlinRun:
    """The state of one connection; `run` returns when every line is acknowledged or stopping."""

    def __init__(self, link: Link, job: JobControl, timeouts: MarlinTimeouts) -> None:
        self.link, self.job, self.timeouts = link, job, timeouts
        self.total = len(job.program)
        self.in_flight: collections.deque[tuple[int, float]] = collections.deque()
        self.next_index = job.confirmed
        self.answer_for_refused = False   # a Resend came: the next "ok" is not a confirmation
        self.handshake_due = job.renumber  # M110 first, to set the firmware's line count
        self.last_traffic = time.monotonic()
        self.silent_attempts = 0

    # -- sending -------------------------------------------------------------------------
    def _transmit(self, index: int) -> None:
        """Write command `index` (or, for index == handshake marker, the M110)."""
        if self.handshake_due:
            text = marlin_line(self.job.confirmed, f"M110 N{self.job.confirmed}")
        else:
            text = marlin_line(index + 1, self.job.program.commands[index])
            self.job.mark_sent(index)
        self.job.log(">", text)
        self.link.write(text.encode("ascii", errors="replace") + b"\n")
        self.in_flight.append((index, time.monotonic()))

    def _maybe_send(self) -> bool:
        """Send the next line if the protocol allows; False when the job is finished."""
        if self.in_flight or self.answer_for_refused:
            return True
        if self.handshake_due:
            self._transmit(self.job.confirmed)
            return True
        if self.job.confirmed >= self.total or self.job.stopping:
            return False
        if self.job.paused:
            return True
        self._transmit(self.next_index)
        return True

    # -- receiving -----------------------------------------------------------------------
    def _on_ok(self) -> None:
        if self.answer_for_refused:
            self.answer_for_refused = False
            if self.in_flight:
                self.in_flight.popleft()
            return
        if not self.in_flight:
            self.job.log("#", "ok without a line in flight (late answer to a repeated line): ignored")
            return
        index, _ = self.in_flight.popleft()
        if self.handshake_due:
            self.handshake_due = False
            self.job.log("#", f"line count set to {self.job.confirmed}")
            return
        if index == self.job.confirmed:
            self.job.mark_confirmed(index + 1)
            self.next_index = index + 1

    def _on_resend(self, number: int) -> None:
        self.answer_for_refused = True
        if self.handshake_due:
            return  # noise before our M110 was refused: the M110 goes out again
        wanted = number - 1  # command index of line `number`
        if 0 < wanted < self.job.confirmed and self.job.confirmed - wanted <= MAX_EXTRA_OKS:
            # Marlin runs line n only right after n - 1, so lines from `number` on did not
            # run: an extra "ok" (a repeated answer) was counted for one of them.
            self.job.log("#", f"the machine asks for line {number}, which an extra 'ok' had "
                              f"counted as done: sending from line {number} again")
            self.job.withdraw_confirmation(wanted)
            self.next_index = wanted
            return
        if wanted < self.job.confirmed:
            self._fail(
                f"the machine asks for line {number} but had acknowledged every line up to "
                f"{self.job.confirmed}: it has lost its place (restarted?), so its queued moves "
                "are gone; check the part, then resume with --from-line"
            )
        if wanted > self.job.sent:
            self._fail(f"the machine asks for line {number}, but only lines up to "
                       f"{self.job.sent} were ever sent: it is not following this job")
        if wanted > self.job.confirmed:
            self.job.mark_confirmed(wanted)  # lines below `number` ran (seen when resuming)
        self.next_index = wanted

    def _on_error(self, text: str) -> None:
        if any(word in text.lower() for word in FATAL_ERROR_WORDS):
            self._fail(f"the machine stopped with {text!r}")
        self.job.log("#", f"firmware error (recoverable, expecting a resend request): {text}")

    def _on_restart(self, text: str) -> None:
        if self.handshake_due:
            return  # the boot banner of a board that resets when the port opens
        self._fail(f"the machine restarted ({text!r}): moves it had queued are lost; check "
                   "the part, then resume with --from-line")

    def _presume_answers_lost(self, why: str) -> None:
        """Nothing is coming for the line(s) in flight: send the oldest unanswered again."""
        self.job.log("#", f"{why}: repeating line {self.job.confirmed + 1}")
        self.in_flight.clear()
        self.answer_for_refused = False
        self.next_index = self.job.confirmed

    def _fail(self, message: str) -> None:
        index = min(self.job.confirmed, self.total - 1)
        raise StreamError(f"{message} (at {self.job.program.path or '<text>'} line "
                          f"{self.job.program.source_lines[index]}, command {index + 1} of {self.total})")

    def _handle(self, text: str) -> None:
        lower = text.lower()
        resend = _RESEND.match(text)
        if lower.startswith("ok"):
            self._on_ok()
        elif resend:
            self._on_resend(int(resend.group(1)))
        elif lower.startswith(("error", "!!")):
            self._on_error(text)
        elif lower == "start":
            self._on_restart(text)
        elif lower == "wait":
            if self.in_flight and time.monotonic() - self.in_flight[0][1] >= self.timeouts.wait_grace:
                self._presume_answers_lost("printer idle ('wait') with a line unanswered")

    def _timeout_for_line_in_flight(self) -> float:
        if self.handshake_due:
            return self.timeouts.handshake
        index = self.in_flight[0][0]
        code = command_code(self.job.program.commands[index]) if index < self.total else ""
        return self.timeouts.long_command if code in LONG_COMMANDS else self.timeouts.answer

    def _check_silence(self) -> None:
        if not self.in_flight:
            if self.answer_for_refused and time.monotonic() - self.last_traffic > self.timeouts.wait_grace:
                # Some firmware sends no "ok" after "Resend": go on with the line it asked for.
                self.answer_for_refused = False
            return
        silence = time.monotonic() - max(self.last_traffic, self.in_flight[-1][1])
        if silence < self._timeout_for_line_in_flight():
            return
        self.silent_attempts += 1
        if self.silent_attempts > self.timeouts.attempts:
            self._fail(f"no answer from {self.link.name} after {self.silent_attempts - 1} "
                       "repeats: is the machine on and set to this baud rate?")
        self._presume_answers_lost(f"no answer for {silence:.1f} s")

    def run(self) -> None:
        self.link.write(b"\n")  # ends any half line left in the firmware's buffer
        while True:
            if self.job.stopping and self.job.emergency:
                MarlinProtocol.emergency_stop(self.link)
                self.job.log(">", "M112 (emergency stop)")
                return
            if not self._maybe_send():
                return
            if self.job.stopping and not self.in_flight and not self.answer_for_refused:
                return
            text = self.link.readline(READ_SLICE)
            if text is None:
                self._check_silence()
                continue
            self.last_traffic = time.monotonic()
            if text:
                self.silent_attempts = 0
                self.job.log("<", text)
                self._handle(text)
