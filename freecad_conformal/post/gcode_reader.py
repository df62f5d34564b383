"""Read the moves of a G-code program, vectorised over the whole text (no per-line Python).

Numbers are read as LinuxCNC reads them: an optional sign, digits and at most one decimal
point, no exponent. `X1e2` is refused (LinuxCNC reads X1 and an E word, Marlin's strtod
X100: the program means different things on different controllers), and so is a word
without a number (`XNaN`, `X`). Comments are `( ... )` and `;` to the end of the line,
whichever comes first: `(a; b)` is one comment, `; a (b` runs to the end of the line.

Only absolute G0/G1 moves in millimetres are replayed; arcs, G91, G20 and G92 with the
machine's axes are refused, and G28 (homing) leaves the position unknown until the next
moves set every axis again.
"""
from __future__ import annotations

import math
import re

import numpy as np

from freecad_conformal.errors import PostError

#: A comment, leftmost first: a parenthesis comment on one line, or ';' to the line's end.
_COMMENT = re.compile(r"\([^)\n]*\)|;[^\n]*")
_BLANKS = b" \t\r%"
#: A number with two decimal points.
_TWO_DOTS = re.compile(rb"\.[0-9]*\.")
_LETTERS = bytes(range(ord("A"), ord("Z") + 1))
_TO_BLANK = bytes.maketrans(_LETTERS + b"\n", b" " * 27)

_REFUSED_G = {2.0: "arcs (G2/G3) are not replayed", 3.0: "arcs (G2/G3) are not replayed",
              91.0: "relative positioning (G91) is not replayed",
              20.0: "inch units (G20) are not replayed",
              92.0: "G92 moves the coordinate system, which the replay does not follow"}
#: G codes whose axis words are not a move target.
_NOT_A_MOVE = (4.0, 10.0, 28.0, 30.0, 53.0, 92.0)


def _classes(data: bytes) -> tuple[np.ndarray, ...]:
    codes = np.frombuffer(data, dtype=np.uint8)
    letter = (codes >= ord("A")) & (codes <= ord("Z"))
    digit = (codes >= ord("0")) & (codes <= ord("9"))
    dot, sign = codes == ord("."), (codes == ord("+")) | (codes == ord("-"))
    return codes, letter, digit, dot, sign, codes == ord("\n")


def _refuse(text: str, data: bytes, offset: int, why: str) -> None:
    line = data.count(b"\n", 0, offset) + 1
    source = text.splitlines()[line - 1].strip() if line <= len(text.splitlines()) else ""
    raise PostError(f"line {line}: {source!r} {why}")


def _uncomment(text: str) -> str:
    """`text` without comments; the regex runs only over the lines that have any (a
    posted program has them in its header), the rest is copied as it is."""
    last = max(text.rfind("("), text.rfind(";"))
    if last < 0:
        return text
    end = text.find("\n", last)
    end = len(text) if end < 0 else end
    return _COMMENT.sub("", text[:end]) + text[end:]


def words(text: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Every word of the program: letters (uint8), values, 1-based lines, and line count.

    Raises PostError naming the line of an unclosed comment, a number with an exponent,
    or anything else that is not a letter followed by a number.
    """
    uncommented = _uncomment(text.upper()).encode("ascii", errors="replace")
    spaced = np.frombuffer(uncommented, dtype=np.uint8)
    e_at = np.flatnonzero(spaced[1:] == ord("E")) + 1
    before_e = spaced[e_at - 1]
    exponent = e_at[((before_e >= ord("0")) & (before_e <= ord("9"))) | (before_e == ord("."))]
    if len(exponent):
        _refuse(text, uncommented, int(exponent[0]), "writes a number with an exponent, which "
                "G-code does not have (LinuxCNC reads the E as a word of its own)")
    data = uncommented.translate(None, _BLANKS)
    codes, letter, digit, dot, sign, newline = _classes(data)

    def ahead(flags: np.ndarray, k: int) -> np.ndarray:
        return np.concatenate((flags[k:], np.zeros(min(k, len(flags)), dtype=bool)))

    number_follows = (ahead(digit, 1) | (ahead(dot, 1) & ahead(digit, 2))
                      | (ahead(sign, 1) & (ahead(digit, 2) | (ahead(dot, 2) & ahead(digit, 3)))))
    line_start = np.concatenate(([True], newline[:-1]))
    bad = ~(letter | digit | dot | sign | newline)
    bad |= sign & ~np.concatenate(([False], letter[:-1]))        # a sign only right after a letter
    bad |= letter & ~number_follows                              # a word without a number
    bad |= ~(letter | newline) & line_start                      # a number without a letter
    two_dots = _TWO_DOTS.search(data)
    if two_dots:
        bad[two_dots.start()] = True
    if bad.any():
        offset = int(np.argmax(bad))
        why = ("has an unclosed comment" if b"(" in data[offset:offset + 1] else
               "is not G-code (a word without a proper number)")
        _refuse(text, data, offset, why)
    values = np.fromstring(data.translate(_TO_BLANK), dtype=float, sep=" ")
    if len(values) != int(letter.sum()):          # cannot happen after the checks above
        raise PostError(f"read {len(values)} numbers for {int(letter.sum())} words")
    lines = (np.cumsum(newline, dtype=np.int32) + 1)[letter]
    return codes[letter], values, lines, int(newline.sum()) + 1


def read_joints(text: str, names: tuple[str, ...],
                rotary_from: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint targets of every G0/G1 block (mm; rotary columns in radians), their lines, and
    the tool selected (last T word, -1 before any) when each block runs.

    `names` are the machine's axis letters in joint order; columns from `rotary_from` on
    are read in degrees. Raises PostError naming the line of anything it cannot replay.
    """
    letters, values, lines, line_count = words(text)
    axis_codes = [ord(name) for name in names]
    g = letters == ord("G")
    axis_lines = lines[np.isin(letters, axis_codes)]
    for code, why in _REFUSED_G.items():
        hit = g & (values == code)
        if code == 92.0:        # G92 E0 is fine; G92 with the machine's axes is not
            hit &= np.isin(lines, axis_lines)
        if hit.any():
            line = int(lines[np.argmax(hit)])
            raise PostError(f"line {line}: {why}: {text.splitlines()[line - 1].strip()}")

    motion = np.full(line_count + 1, -1.0)           # modal G0/G1 by line, -1 before any
    moving = g & ((values == 0.0) | (values == 1.0))
    motion[lines[moving]] = values[moving]
    set_at = np.where(motion >= 0, np.arange(line_count + 1), 0)
    np.maximum.accumulate(set_at, out=set_at)
    motion = motion[set_at]
    skip = np.zeros(line_count + 1, dtype=bool)
    skip[lines[g & np.isin(values, _NOT_A_MOVE)]] = True
    homed = np.zeros(line_count + 1, dtype=bool)
    homed[lines[g & ((values == 28.0) | (values == 30.0))]] = True

    targets = np.full((line_count + 1, len(names)), np.nan)
    has_axis = np.zeros(line_count + 1, dtype=bool)
    for k, name in enumerate(names):
        pick = (letters == ord(name)) & ~skip[lines] & (motion[lines] >= 0)
        value = values[pick] if k < rotary_from else np.radians(values[pick])
        targets[lines[pick], k] = value          # the last word of a letter on a line wins
        has_axis[lines[pick]] = True
    rows = np.flatnonzero(has_axis | homed)
    if not has_axis.any():
        raise PostError("the program has no G0/G1 move for the machine's axes")
    block = targets[rows]
    reset = homed[rows] & ~has_axis[rows]
    index = np.where(~np.isnan(block) | reset[:, None], np.arange(len(rows))[:, None], 0)
    np.maximum.accumulate(index, axis=0, out=index)
    filled = np.take_along_axis(block, index, axis=0)
    keep = ~reset
    filled, move_lines = filled[keep], rows[keep]
    unknown = np.isnan(filled).any(axis=1)
    if unknown.any():
        i = int(np.argmax(unknown))
        missing = [n for n, v in zip(names, filled[i]) if math.isnan(v)]
        where = "the first move" if i == 0 else f"the move on line {int(move_lines[i])}"
        raise PostError(f"{where} does not set axis/axes {', '.join(missing)} (position unknown "
                        "at the start or after homing)")
    tool = np.full(line_count + 1, -1.0)
    t_words = letters == ord("T")
    tool[lines[t_words]] = values[t_words]
    tool_set = np.where(tool >= 0, np.arange(line_count + 1), 0)
    np.maximum.accumulate(tool_set, out=tool_set)
    tools = np.where(tool_set[move_lines] > 0, tool[tool_set[move_lines]], -1).astype(np.int64)
    return filled, move_lines, tools
