"""package.xml as FreeCAD (and so the Addon Manager) reads it."""
from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from tests.conftest import PROJECT_ROOT

PACKAGE_XML = PROJECT_ROOT / "package.xml"
NS = {"p": "https://wiki.freecad.org/Package_Metadata"}


@pytest.fixture(scope="module")
def metadata(App):
    return App.Metadata(str(PACKAGE_XML))


def test_freecad_loads_the_metadata(metadata):
    assert metadata.Name == "Conformal"
    assert metadata.Version
    assert metadata.supportsCurrentFreeCAD()
    assert metadata.FreeCADMin == "0.20.0"


def test_workbench_entry(metadata):
    (workbench,) = metadata.Content["workbench"]
    assert workbench.Classname == "ConformalWorkbench"
    assert workbench.Subdirectory == "./"
    assert workbench.FreeCADMin == "0.20.0"
    assert workbench.supportsCurrentFreeCAD()
    assert (PROJECT_ROOT / workbench.Icon).is_file()
    assert (PROJECT_ROOT / metadata.Icon).is_file()


def test_workbench_class_is_the_one_initgui_registers():
    source = (PROJECT_ROOT / "InitGui.py").read_text(encoding="utf-8")
    assert "class ConformalWorkbench(" in source
    assert "addWorkbench(ConformalWorkbench())" in source


def test_python_dependencies(metadata):
    # FreeCAD 0.20's Metadata.Depend drops the type and optional attributes: read the XML.
    assert [d["package"] for d in metadata.Depend] == ["numpy", "shapely", "matplotlib",
                                                       "pyserial"]
    depends = ET.parse(PACKAGE_XML).getroot().findall("p:depend", NS)
    found = {d.text.strip(): (d.get("type"), d.get("optional", "false")) for d in depends}
    assert found == {"numpy": ("python", "false"), "shapely": ("python", "false"),
                     "matplotlib": ("python", "false"), "pyserial": ("python", "true")}
