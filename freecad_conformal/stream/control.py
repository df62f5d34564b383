"""What a wire protocol (Marlin, grbl) needs from the job that drives it.

The Streamer implements this; protocols only talk to a Link and to a JobControl, so they
can be read (and tested) without threads, progress bars or state files in view.
"""
from __future__ import annotations

from typing import Protocol

from freecad_conformal.stream.port import Link
from freecad_conformal.stream.program import Program


class JobControl(Protocol):
    """The job as seen by a protocol.

    Attributes:
        program: the commands to send.
        confirmed: index of the first command the machine has not acknowledged.
        sent: one past the highest command index ever written to the port.
        renumber: True to start with a fresh line count at `confirmed` (new job or a
            resume from a line the user chose); False to resume by the machine's own count.
    """

    program: Program
    renumber: bool

    @property
    def confirmed(self) -> int:
        """Index of the first command the machine has not acknowledged (read-only here:
        the streamer advances it as answers come)."""

    @property
    def sent(self) -> int:
        """One past the highest command index ever written to the port."""

    @property
    def paused(self) -> bool:
        """The user asked to pause: send nothing new (a grbl machine also holds its feed)."""

    @property
    def stopping(self) -> bool:
        """The user asked to abort: send nothing new, collect the answers still due, return."""

    @property
    def emergency(self) -> bool:
        """The abort is an emergency stop: tell the machine to halt at once."""

    def mark_sent(self, index: int) -> None:
        """Command `index` was written to the port."""

    def mark_confirmed(self, count: int) -> None:
        """Commands 0..count-1 are acknowledged by the machine."""

    def withdraw_confirmation(self, count: int) -> None:
        """Only commands 0..count-1 are acknowledged after all (an extra "ok" was counted)."""

    def log(self, direction: str, text: str) -> None:
        """Record one line of traffic: direction '>' (to machine), '<' (from it) or '#' (note)."""


class WireProtocol(Protocol):
    """A way of feeding a machine: Marlin's line numbers and oks, grbl's character counting."""

    name: str

    def check(self, job: JobControl) -> None:
        """Refuse, before the port is opened, a program this firmware cannot take.

        Raises:
            StreamError: naming the first file line at fault.
        """

    def run(self, link: Link, job: JobControl) -> None:
        """Send job.program from job.confirmed until every command is acknowledged or the job stops.

        Raises:
            StreamError: on a machine error, a lost connection (PortLost) or no answer.
        """
