"""The batch report: one row per part, written as CSV and JSON (atomically), and a text table.

Rows are plain dicts with exactly `COLUMNS` as keys so they cross process and network
boundaries (multiprocessing, Dask) without custom classes.
"""
from __future__ import annotations

import csv
import io
import json
import os
from typing import Any, Sequence

from freecad_conformal.fileio import write_text_atomic

#: Report columns, in order. material_mm3 is the deposited volume (bead width x layer height
#: x path length); time_s the estimated machine time; plan_s the wall time spent planning.
COLUMNS = ("part", "file", "body", "status", "subparts", "layers", "material_mm3", "time_s",
           "plan_s", "gcode", "gcode_bytes", "error")

OK = "ok"
FAILED = "failed"


def new_row(part: str, file: str, body: str = "") -> dict[str, Any]:
    """A row with every column present; numbers None until the part is planned."""
    row: dict[str, Any] = dict.fromkeys(COLUMNS)
    row.update(part=part, file=file, body=body, status=FAILED, error="")
    return row


def failed_row(part: str, file: str, error: str, body: str = "") -> dict[str, Any]:
    row = new_row(part, file, body)
    row["error"] = error
    return row


def counts(rows: Sequence[dict]) -> dict[str, int]:
    """{"parts": n, "ok": n, "failed": n}."""
    ok = sum(row["status"] == OK for row in rows)
    return {"parts": len(rows), OK: ok, FAILED: len(rows) - ok}


def csv_text(rows: Sequence[dict]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({key: "" if row[key] is None else row[key] for key in COLUMNS})
    return buffer.getvalue()


def json_text(rows: Sequence[dict], settings: dict[str, Any]) -> str:
    document = {"summary": counts(rows), "settings": settings,
                "parts": [{key: row[key] for key in COLUMNS} for row in rows]}
    return json.dumps(document, indent=2) + "\n"


def write_report(rows: Sequence[dict], csv_path: str | os.PathLike, json_path: str | os.PathLike,
                 settings: dict[str, Any]) -> None:
    """Both files, each whole or not at all."""
    write_text_atomic(csv_path, csv_text(rows))
    write_text_atomic(json_path, json_text(rows, settings))


def table(rows: Sequence[dict]) -> str:
    """A short human summary: one line per part, then the totals."""
    lines = [f"{'part':32} {'status':6} {'sub':>3} {'layers':>6} {'cm3':>8} {'time':>9} "
             f"{'bytes':>9}  error"]
    for row in rows:
        if row["status"] == OK:
            minutes, seconds = divmod(int(round(row["time_s"])), 60)
            lines.append(f"{row['part'][:32]:32} {OK:6} {row['subparts']:3d} {row['layers']:6d} "
                         f"{row['material_mm3'] / 1000.0:8.3f} {minutes:6d}:{seconds:02d} "
                         f"{row['gcode_bytes']:9d}")
        else:
            lines.append(f"{row['part'][:32]:32} {FAILED:6} {'':3} {'':6} {'':8} {'':9} {'':9}  "
                         f"{row['error']}")
    total = counts(rows)
    lines.append(f"{total['parts']} parts: {total[OK]} ok, {total[FAILED]} failed")
    return "\n".join(lines) + "\n"
