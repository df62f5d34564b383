"""The per-part task: load, decompose, plan, post; return plain data.

`run_part` is a module-level function of picklable arguments, so a process pool or a Dask
worker can run it. It never writes output: the coordinator writes every G-code file, so
remote workers need no shared disk. It never raises for a bad part either: the reason goes
in the row, and the rest of the batch carries on.
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

from freecad_conformal.jobs.batch.jobs import FCSTD_SUFFIX, PartJob
from freecad_conformal.jobs.batch.report import OK, new_row
from freecad_conformal.errors import ConformalError


def load_part(job: PartJob):
    """The job's shape: the whole file, or one body of an FCStd.

    With `job.data` set the bytes are read from a temporary copy, not from `job.path`.
    """
    if job.data is None:
        return _load(Path(job.path), job.body)
    with tempfile.TemporaryDirectory(prefix="conformal-batch-") as folder:
        copy = Path(folder) / Path(job.path).name
        copy.write_bytes(job.data)
        return _load(copy, job.body)


def _load(path: Path, body: str):
    if path.suffix.lower() == FCSTD_SUFFIX and body:
        from freecad_conformal.jobs.batch.fcstd import body_shape

        return body_shape(path, body)
    from freecad_conformal.geometry.solids import load_shape

    return load_shape(path)


def plan_gcode(shape, options, part: str):
    """The plan command's pipeline (options checked first: it is quick) -> JobResult."""
    from freecad_conformal.jobs.job import plan_job

    return plan_job(shape, options, part=part)


def run_part(job: PartJob, options) -> dict[str, Any]:
    """Plan and post one part.

    Args:
        job: the part.
        options: a planning.job.PlanOptions.
    Returns:
        {"row": report row (see report.COLUMNS; "gcode" is filled in by the coordinator
        once the file is written), "gcode": the program text, or None when the part failed}.
    """
    row = new_row(job.part, job.path, job.body_label)
    start = time.perf_counter()
    text = None
    try:
        result = plan_gcode(load_part(job), options, Path(job.output).stem or job.part)
        text = result.post.text
        row.update(status=OK, subparts=len(result.subparts),
                   layers=int(sum(sub.layers for sub in result.subparts)),
                   material_mm3=round(result.material_volume, 3), time_s=round(result.time_s, 1),
                   gcode_bytes=len(text.encode("utf-8")))
    except ConformalError as exc:
        row["error"] = str(exc)
    # A batch must outlive a bug or an OCC failure on one part: report it and go on.
    except Exception as exc:  # noqa: BLE001
        row["error"] = f"internal error ({type(exc).__name__}): {exc}"
    row["plan_s"] = round(time.perf_counter() - start, 3)
    return {"row": row, "gcode": text}
