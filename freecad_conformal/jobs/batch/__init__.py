"""Batch export: plan and post many parts (files, globs, every solid body of an FCStd).

- `jobs.py`: expand the inputs into one `PartJob` per part; inputs that cannot become a job
  (missing file, unknown suffix, an FCStd without solid bodies) become failed rows at once.
- `fcstd.py`: the solid bodies of an FreeCAD document, each a separate part.
- `worker.py`: `run_part(job, options)`, the picklable per-part task: it loads the part in
  the worker, plans and posts it, and returns plain data (a report row and the G-code text).
- `runners.py`: where the tasks run: in-process, a local process pool, or a Dask cluster.
- `report.py`: the CSV/JSON report, written atomically.
- `run.py`: `run_batch`, the whole batch: jobs -> runner -> G-code files + report.
"""
