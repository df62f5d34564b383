"""A dependency-free progress bar on stderr for long command line runs."""
from __future__ import annotations

import sys
import time
from typing import IO


class Progress:
    """Progress over `total` steps; draws only on a terminal unless `force` is set.

    Redraws at most every `interval` seconds so it costs nothing in tight loops.
    """

    def __init__(self, total: int, label: str = "", stream: IO | None = None,
                 force: bool = False, interval: float = 0.1) -> None:
        self.total = max(int(total), 0)
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = force or bool(getattr(self.stream, "isatty", lambda: False)())
        self.interval = interval
        self.done = 0
        self._start = time.monotonic()
        self._last_draw = 0.0

    def update(self, steps: int = 1) -> None:
        self.done = min(self.done + steps, self.total) if self.total else self.done + steps
        now = time.monotonic()
        if self.enabled and (now - self._last_draw >= self.interval or self.done == self.total):
            self._last_draw = now
            self._draw(now)

    def _draw(self, now: float) -> None:
        width = 30
        fraction = self.done / self.total if self.total else 1.0
        filled = int(round(width * fraction))
        elapsed = now - self._start
        eta = elapsed * (1 - fraction) / fraction if fraction > 0 else 0.0
        self.stream.write(
            f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] "
            f"{self.done}/{self.total} {100 * fraction:5.1f}% {elapsed:5.1f}s eta {eta:5.1f}s"
        )
        self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self._draw(time.monotonic())
            self.stream.write("\n")
            self.stream.flush()

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
