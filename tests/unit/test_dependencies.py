"""The message a user sees when the workbench activates without numpy or shapely."""
from __future__ import annotations

from freecad_conformal.dependencies import REQUIRED, install_hint, missing


def test_nothing_is_said_when_everything_imports():
    assert missing(lambda name: object()) == []
    assert install_hint([]) == ""


def test_a_debian_freecad_gets_apt_not_a_pip_that_pulls_numpy_2():
    absent = missing(lambda name: None if name == "shapely" else object())
    assert [name for name, _, _ in absent] == ["shapely"]
    text = install_hint(absent, python="/usr/bin/python3", version=(3, 11))
    assert "needs shapely" in text and "apt-get install python3-shapely" in text
    assert "numpy 2" in text and "--break-system-packages`" in text


def test_an_appimage_or_windows_freecad_gets_a_pinned_pip_line():
    text = install_hint([e for e in REQUIRED if e[0] in ("numpy", "shapely")],
                        python="/tmp/.mount_FreeCAD/usr/bin/python", version=(3, 11))
    assert "'numpy<2'" in text and "'shapely>=2,<2.1'" in text and "--user" in text
