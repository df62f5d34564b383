"""The saved state of a streaming job: enough to resume without losing or repeating a line.

The state file is JSON written atomically (never half-written), so a crash while saving
leaves the previous state intact.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from freecad_conformal.errors import StreamError
from freecad_conformal.fileio import write_text_atomic

STATE_FORMAT = "conformal-stream-state"
STATE_VERSION = 1

#: Job statuses a state file may record.
STATUSES = ("running", "paused", "aborted", "disconnected", "failed", "done")


@dataclass
class StreamState:
    """Where a job stands.

    Attributes:
        program: path of the program file.
        program_sha256: digest of the program text; a resume refuses another program.
        protocol: "marlin" or "grbl".
        total: number of commands in the program.
        confirmed: commands 0..confirmed-1 were acknowledged by the machine (executed or
            queued for execution); streaming resumes at index `confirmed`.
        sent: commands 0..sent-1 were written to the port at least once. Commands in
            confirmed..sent-1 were in flight when the job stopped: Marlin's line numbers tell
            on resume whether they ran; grbl has none, so they are reported as uncertain.
        status: one of STATUSES.
        message: why the job stopped ("" while running or done).
        port: the port last used.
        updated: Unix time of the last save.
    """

    program: str
    program_sha256: str
    protocol: str
    total: int
    confirmed: int = 0
    sent: int = 0
    status: str = "running"
    message: str = ""
    port: str = ""
    updated: float = field(default_factory=time.time)

    def to_json(self) -> str:
        record = {"format": STATE_FORMAT, "version": STATE_VERSION, **asdict(self)}
        return json.dumps(record, indent=2, sort_keys=True) + "\n"


def save_state(path: str | os.PathLike, state: StreamState) -> None:
    """Write `state` atomically to `path`."""
    state.updated = time.time()
    try:
        write_text_atomic(path, state.to_json())
    except OSError as exc:
        raise StreamError(f"stream state {path} cannot be written: {exc.strerror}") from None


def load_state(path: str | os.PathLike) -> StreamState:
    """Read and check a state file.

    Raises:
        StreamError: when the file is missing, not a state file, or inconsistent.
    """
    file = Path(path)
    try:
        record = json.loads(file.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise StreamError(f"stream state {file} does not exist") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise StreamError(f"stream state {file} cannot be read: {exc}") from None
    if not isinstance(record, dict) or record.get("format") != STATE_FORMAT:
        raise StreamError(f"{file} is not a stream state file (format {record.get('format') if isinstance(record, dict) else None!r})")
    if record.get("version") != STATE_VERSION:
        raise StreamError(f"stream state {file} has version {record.get('version')!r}; this version reads {STATE_VERSION}")
    expected: dict[str, type | tuple[type, ...]] = {"program": str, "program_sha256": str, "protocol": str, "total": int,
                "confirmed": int, "sent": int, "status": str, "message": str, "port": str,
                "updated": (int, float)}
    for key, kind in expected.items():
        if not isinstance(record.get(key), kind) or isinstance(record.get(key), bool):
            raise StreamError(f"stream state {file}: field {key!r} is {record.get(key)!r}, expected {kind}")
    state = StreamState(**{key: record[key] for key in expected})
    if state.status not in STATUSES:
        raise StreamError(f"stream state {file}: status {state.status!r} is not one of {STATUSES}")
    if not 0 <= state.confirmed <= state.sent <= state.total:
        raise StreamError(
            f"stream state {file}: counts confirmed={state.confirmed}, sent={state.sent}, "
            f"total={state.total} are inconsistent (need 0 <= confirmed <= sent <= total)"
        )
    return state
