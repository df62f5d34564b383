"""Which of the workbench's Python packages are missing, and how to install them for the
FreeCAD at hand. By-hand installs into Debian's FreeCAD have no shapely, and the obvious
`pip install --break-system-packages shapely` pulls numpy 2 into the system Python, which
breaks Debian 12's compiled matplotlib and scipy."""
from __future__ import annotations

import importlib.util
import sys
from typing import Callable, Sequence

#: (module, pip requirement that keeps Debian 12's numpy 1.x, Debian package)
REQUIRED = (("numpy", "numpy<2", "python3-numpy"),
            ("shapely", "shapely>=2,<2.1", "python3-shapely"),
            ("matplotlib", "matplotlib", "python3-matplotlib"))


def missing(find: Callable[[str], object] = importlib.util.find_spec,
            required: Sequence[tuple[str, str, str]] = REQUIRED) -> list[tuple[str, str, str]]:
    return [entry for entry in required if find(entry[0]) is None]


def install_hint(absent: Sequence[tuple[str, str, str]], python: str = sys.executable,
                 version: tuple[int, int] = sys.version_info[:2]) -> str:
    """What to tell the user: the missing modules and one command for their FreeCAD."""
    if not absent:
        return ""
    names = ", ".join(name for name, _, _ in absent)
    debs = " ".join(deb for _, _, deb in absent)
    pins = " ".join(f"'{pip}'" for _, pip, _ in absent)
    lines = [f"Conformal needs {names}, which this FreeCAD's Python cannot import."]
    if python.startswith("/usr/") and version >= (3, 11):
        lines.append(f"Debian/Ubuntu FreeCAD: sudo apt-get install {debs}")
        lines.append("(not `pip install --break-system-packages`: it pulls numpy 2, which breaks "
                     "Debian's own matplotlib and scipy)")
    else:
        lines.append(f"In FreeCAD's Python console: import subprocess, sys; "
                     f"subprocess.check_call([sys.executable, '-m', 'pip', 'install', '--user', {pins.replace(' ', ', ')}])")
    lines.append("or use Tools > Addon manager, which installs them for FreeCAD.")
    return "\n".join(lines) + "\n"
