"""A G-code program as the streamer sees it: the commands to send, each with its file line.

Pure Python: no serial port, no FreeCAD. Comments and blank lines are never sent; every
command keeps the number of the file line it came from so that logs, progress and
`--from-line` speak the user's language (the line numbers an editor shows).
"""
from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

from freecad_conformal.errors import StreamError

#: `( ... )` is an inline comment in RS274/NGC and grbl; `;` starts a comment to the end of
#: the line (RepRap/Marlin and grbl alike). Whichever starts first wins: `(a; b)` is one
#: comment, and `; a (b` runs to the end of the line (the regex scans left to right).
_COMMENT = re.compile(r"\([^)]*\)|;.*$")
#: A line number the file already carries (`N120 G1 ...`): the streamer numbers lines itself.
_FILE_LINE_NUMBER = re.compile(r"^N\d+\s*", re.IGNORECASE)
#: A checksum the file already carries (`...*57`): recomputed by the streamer.
_FILE_CHECKSUM = re.compile(r"\*\d+\s*$")
#: M110 sets the firmware's line counter, which belongs to the streamer during a job.
_M110 = re.compile(r"^M0*110(\D|$)", re.IGNORECASE)


@dataclass(frozen=True)
class Program:
    """The commands of a G-code file in order, with where each came from.

    Attributes:
        path: the file the program was read from ("" for programs made from text).
        commands: the commands to send, comments and blank lines removed.
        source_lines: 1-based file line of each command (same length as `commands`).
        sha256: digest of the file's bytes, to check that a saved state belongs to it.
    """

    path: str
    commands: tuple[str, ...]
    source_lines: tuple[int, ...]
    sha256: str

    def __len__(self) -> int:
        return len(self.commands)

    def index_of_file_line(self, file_line: int) -> int:
        """The index of the first command at or after 1-based `file_line`.

        Raises:
            StreamError: when no command starts at or after that line.
        """
        for index, line in enumerate(self.source_lines):
            if line >= file_line:
                return index
        raise StreamError(
            f"--from-line {file_line}: program {self.path or '<text>'} has no command at or "
            f"after that line (last command is on line {self.source_lines[-1] if self.source_lines else 0})"
        )


def clean_command(raw: str) -> str:
    """One file line without comments, file line numbers, checksums or outer blanks."""
    text = _COMMENT.sub("", raw).strip()
    text = _FILE_CHECKSUM.sub("", _FILE_LINE_NUMBER.sub("", text)).strip()
    return text


def program_from_text(text: str, path: str = "") -> Program:
    """Parse G-code text into a Program.

    Raises:
        StreamError: when the program sets line numbers itself (M110) or has no command.
    """
    commands: list[str] = []
    source_lines: list[int] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        command = clean_command(raw)
        if not command or command == "%":
            continue  # `%` only marks tape start/end in RS274 files
        if _M110.match(command):
            raise StreamError(
                f"{path or '<text>'} line {number}: {command!r} sets the firmware's line "
                "numbers, which the streamer owns during a job; remove it"
            )
        commands.append(command)
        source_lines.append(number)
    if not commands:
        raise StreamError(f"program {path or '<text>'} has no G-code command to send")
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return Program(path, tuple(commands), tuple(source_lines), digest)


def load_program(path: str | os.PathLike) -> Program:
    """Read a G-code file.

    Raises:
        StreamError: when the file cannot be read, is not text, or has no command.
    """
    file = Path(path)
    try:
        text = file.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise StreamError(f"program {file} does not exist") from None
    except UnicodeDecodeError as exc:
        raise StreamError(f"program {file} is not UTF-8/ASCII text (byte {exc.start})") from None
    except OSError as exc:
        raise StreamError(f"program {file} cannot be read: {exc.strerror}") from None
    return program_from_text(text, str(file))


def marlin_checksum(payload: str) -> int:
    """RepRap/Marlin checksum: XOR of every byte of `N<n> <command>` before the `*`."""
    checksum = 0
    for byte in payload.encode("ascii", errors="replace"):
        checksum ^= byte
    return checksum


def marlin_line(number: int, command: str) -> str:
    """`N<number> <command>*<checksum>` without the newline."""
    payload = f"N{number} {command}"
    return f"{payload}*{marlin_checksum(payload)}"


def grbl_line(command: str) -> str:
    """grbl's compact form: no blanks, upper case (every byte counts in its 127-byte buffer)."""
    return re.sub(r"\s+", "", command).upper()
