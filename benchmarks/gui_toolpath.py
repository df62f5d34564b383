"""Toolpath display speed in the real FreeCAD GUI (Xvfb): our single indexed line set with
per-move colours against the peer layout of one Coin node group per segment, built and
rendered in the same run. Prints times and ratios (peer / ours; above 1 means we are faster).

    .venv/bin/python benchmarks/gui_toolpath.py
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.gui.freecad_gui import run_gui_check  # noqa: E402

#: (poses, poses per segment): short segments are where one node per segment hurts.
CASES = [(10_000, 10), (100_000, 10), (100_000, 100)]


def main() -> int:
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        params = {"artifacts": str(tmp), "cases": CASES}
        check = ROOT / "benchmarks" / "gui_toolpath_check.py"
        # the check imports helix_toolpath from the GUI test checks beside it
        shutil.copy(ROOT / "tests" / "gui" / "checks" / "objects_check.py", tmp / "objects_check.py")
        shutil.copy(check, tmp / check.name)
        result = run_gui_check(tmp / check.name, tmp, params, timeout=600)
    print(f"{'poses':>8} {'segments':>8} {'build ours':>10} {'build peer':>10} {'ratio':>6} "
          f"{'render ours':>11} {'render peer':>11} {'ratio':>6}")
    for r in result["results"]:
        print(f"{r['points']:>8} {r['segments']:>8} {r['ours_build']:>9.3f}s {r['peer_build']:>9.3f}s "
              f"{r['peer_build'] / r['ours_build']:>6.1f} {r['ours_render']:>10.3f}s "
              f"{r['peer_render']:>10.3f}s {r['peer_render'] / r['ours_render']:>6.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
