"""A small grbl 1.1 SIMULATOR on a pseudo-terminal (not a real peer: no grbl runs here).

It models the parts of grbl that the streaming protocol depends on:
  * a 127-byte serial receive buffer filled as bytes arrive; bytes that do not fit are
    lost, as on the real UART, and counted in `overflowed_bytes`;
  * a line parser that takes bytes out of that buffer one line at a time, answers "ok" or
    "error:N" (1 no letter, 2 bad number, 11 line too long, 20 unsupported command), and
    blocks while its 16-block planner is full (which is when the receive buffer fills);
  * a motion thread that executes one planner block every `block_seconds`, recording the
    command in `executed`, and stops while in feed hold;
  * real-time bytes '?' (status report), '!' (feed hold), '~' (cycle start) and Ctrl-X
    (soft reset: buffers cleared, banner sent again), acted on at arrival.
"""
from __future__ import annotations

import contextlib
import os
import re
import select
import threading
import tty

RX_BUFFER_BYTES = 127
PLANNER_BLOCKS = 16
LINE_BUFFER_BYTES = 80
BANNER = "Grbl 1.1h ['$' for help]"
SUPPORTED_G = {0, 1, 2, 3, 4, 10, 17, 18, 19, 20, 21, 28, 30, 40, 43.1, 49, 53, 54, 55, 56,
               57, 58, 59, 61, 80, 90, 91, 92, 93, 94}
SUPPORTED_M = {0, 1, 2, 3, 4, 5, 7, 8, 9, 30, 56}
#: grblHAL adds tool changes (M6), synchronised digital outputs (M62-M65) and tool length
#: offsets (G43 with an H word, G49).
GRBLHAL_G = SUPPORTED_G | {43}
GRBLHAL_M = SUPPORTED_M | {6, 62, 63, 64, 65}
_WORD = re.compile(r"([A-Z])([-+]?(?:\d+\.?\d*|\.\d+))")


def parse_error(line: str, grblhal: bool = False) -> int:
    """grbl's error code for `line` (already without blanks), 0 when it is accepted;
    `grblhal` accepts grblHAL's extra G and M codes too."""
    supported_g, supported_m = (GRBLHAL_G, GRBLHAL_M) if grblhal else (SUPPORTED_G, SUPPORTED_M)
    if len(line) >= LINE_BUFFER_BYTES:
        return 11
    if line.startswith("$") or not line:
        return 0
    position = 0
    while position < len(line):
        if not line[position].isalpha():
            return 1
        match = _WORD.match(line, position)
        if match is None:
            return 2
        letter, value = match.group(1), float(match.group(2))
        if (letter == "G" and value not in supported_g) or (letter == "M" and value not in supported_m):
            return 20
        position = match.end()
    return 0


class GrblSimulator:
    """Run the simulator; `port` is the pseudo-terminal path a streamer opens."""

    def __init__(self, block_seconds: float = 0.0005) -> None:
        self.block_seconds = block_seconds
        self.executed: list[str] = []
        self.overflowed_bytes = 0
        self.peak_rx_bytes = 0
        self.holds = 0
        self._rx = bytearray()
        self._planner: list[str] = []
        self._held = False
        self._stop = threading.Event()
        self._changed = threading.Condition()
        self._master, slave = os.openpty()
        tty.setraw(slave)
        self._slave = slave
        self.port = os.ttyname(slave)
        self._send(BANNER)
        self._threads = [threading.Thread(target=loop, daemon=True)
                         for loop in (self._receive, self._parse, self._move)]
        for thread in self._threads:
            thread.start()

    def _send(self, text: str) -> None:
        with contextlib.suppress(OSError):
            os.write(self._master, (text + "\r\n").encode("ascii"))

    def _realtime(self, byte: int) -> bool:
        if byte == ord("?"):
            state = "Hold" if self._held else ("Run" if self._planner else "Idle")
            self._send(f"<{state}|MPos:0.000,0.000,0.000|FS:0,0>")
        elif byte == ord("!"):
            self._held = True
            self.holds += 1
        elif byte == ord("~"):
            self._held = False
        elif byte == 0x18:
            self._rx.clear()
            self._planner.clear()
            self._held = False
            self._send(BANNER)
        else:
            return False
        return True

    def _receive(self) -> None:
        """The UART: every byte that arrives goes into the receive buffer if there is room."""
        while not self._stop.is_set():
            try:
                ready, _, _ = select.select([self._master], [], [], 0.05)
                chunk = os.read(self._master, 4096) if ready else b""
            except OSError:
                return
            with self._changed:
                for byte in chunk:
                    if self._realtime(byte):
                        continue
                    if len(self._rx) >= RX_BUFFER_BYTES:
                        self.overflowed_bytes += 1
                        continue
                    self._rx.append(byte)
                self.peak_rx_bytes = max(self.peak_rx_bytes, len(self._rx))
                self._changed.notify_all()

    def _next_line(self) -> str | None:
        with self._changed:
            while not self._stop.is_set():
                ends = [i for i in (self._rx.find(b"\n"), self._rx.find(b"\r")) if i >= 0]
                if ends:
                    end = min(ends)
                    line = bytes(self._rx[:end]).decode("ascii", errors="replace")
                    del self._rx[:end + 1]
                    return line
                self._changed.wait(0.05)
        return None

    def _parse(self) -> None:
        while (line := self._next_line()) is not None:
            line = re.sub(r"\s+", "", line).upper()
            code = parse_error(line)
            if code:
                self._send(f"error:{code}")
                continue
            if line and not line.startswith("$"):
                with self._changed:
                    while len(self._planner) >= PLANNER_BLOCKS and not self._stop.is_set():
                        self._changed.wait(0.05)
                    self._planner.append(line)
                    self._changed.notify_all()
            self._send("ok")

    def _move(self) -> None:
        while not self._stop.is_set():
            with self._changed:
                if self._held or not self._planner:
                    self._changed.wait(0.01)
                    continue
                block = self._planner.pop(0)
                self.executed.append(block)
                self._changed.notify_all()
            self._stop.wait(self.block_seconds)

    def wait_idle(self, timeout: float = 5.0) -> None:
        """Wait until the planner has executed every block it took (motion finished)."""
        with self._changed:
            self._changed.wait_for(lambda: not self._planner and not self._rx, timeout)

    def close(self) -> None:
        self._stop.set()
        with self._changed:
            self._changed.notify_all()
        for thread in self._threads:
            thread.join(timeout=2)
        for fd in (self._master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)
