"""The house's import rules (docs/ARCHITECTURE.md): data flows one way through the rooms,
pure rooms never import FreeCAD or Qt, only gui/ touches the screen, and no module imports
one that imports it back. Read from the source, so a new import that breaks a rule fails."""
from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "freecad_conformal"

#: Rooms from the bottom up: a room may import its own modules and rooms below it only.
ROOMS = [
    {"package", "errors", "tolerances", "fileio", "progress", "freecad_env", "child_python",
     "settings", "dependencies", "shapely_speed"},
    {"toolpath"},
    {"process", "post", "stream"},
    {"geometry"},
    {"decomposition"},
    {"layers"},
    {"paths"},
    {"jobs"},
    {"objects"},
    {"gui"},
    {"commands"},
    {"cli", "__main__"},
]
RANK = {room: level for level, rooms in enumerate(ROOMS) for room in rooms}
#: Rooms that run in any Python with numpy: no FreeCAD, no Qt, not even lazily.
PURE = {"errors", "tolerances", "fileio", "progress", "settings", "dependencies", "shapely_speed",
        "toolpath", "process", "post", "stream"}
FREECAD_MODULES = {"FreeCAD", "Part", "Mesh", "MeshPart", "FreeCADGui", "Import"}
SCREEN_MODULES = {"FreeCADGui", "PySide", "PySide2", "PySide6", "pivy"}


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _room(module: str) -> str:
    parts = module.split(".")
    return "package" if len(parts) == 1 else parts[1]


def _imports(path: Path) -> list[tuple[str, int]]:
    """(imported module, line) for every import in the file, lazy ones included."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.append((node.module, node.lineno))
            # `from package import submodule` imports the submodule
            found += [(f"{node.module}.{alias.name}", node.lineno) for alias in node.names
                      if (PACKAGE.parent / f"{node.module}.{alias.name}".replace(".", "/")).exists()
                      or (PACKAGE.parent / (f"{node.module}.{alias.name}".replace(".", "/") + ".py")).exists()]
    return found


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _package_imports():
    for module, path in MODULES.items():
        for target, line in _imports(path):
            yield module, path, target, line


def test_every_room_is_ranked():
    rooms = {_room(m) for m in MODULES}
    assert rooms <= set(RANK), f"rooms without a rank in ROOMS: {sorted(rooms - set(RANK))}"


def test_data_flows_one_way():
    upward = []
    for module, path, target, line in _package_imports():
        if not target.startswith("freecad_conformal"):
            continue
        source, destination = _room(module), _room(target)
        if RANK[destination] > RANK[source]:
            upward.append(f"{path.relative_to(PACKAGE.parent)}:{line} {source} imports {target}")
    assert not upward, "imports against the flow:\n" + "\n".join(upward)


def test_pure_rooms_import_no_freecad_and_only_gui_imports_the_screen():
    broken = []
    for module, path, target, line in _package_imports():
        top = target.split(".")[0]
        room = _room(module)
        if room in PURE and top in FREECAD_MODULES | SCREEN_MODULES:
            broken.append(f"{path.relative_to(PACKAGE.parent)}:{line} pure {room} imports {target}")
        elif room != "gui" and top in SCREEN_MODULES:
            broken.append(f"{path.relative_to(PACKAGE.parent)}:{line} {room} imports {target}")
    assert not broken, "\n".join(broken)


def test_no_import_cycles_between_modules():
    graph = defaultdict(set)
    for module, _, target, _ in _package_imports():
        if target in MODULES and target != module and target != "freecad_conformal":
            if not MODULES[target].name == "__init__.py":   # a package's re-exports
                graph[module].add(target)
    cycles = []
    for start in MODULES:
        seen, stack = set(), [(start, [start])]
        while stack:
            node, trail = stack.pop()
            for nxt in graph[node]:
                if nxt == start:
                    cycles.append(" -> ".join(trail + [start]))
                elif nxt not in seen:
                    seen.add(nxt)
                    stack.append((nxt, trail + [nxt]))
    assert not cycles, "import cycles:\n" + "\n".join(sorted(set(cycles)))


def test_no_private_name_is_imported_from_another_module():
    users = []
    for path in MODULES.values():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("freecad_conformal"):
                users += [f"{path.relative_to(PACKAGE.parent)}:{node.lineno} imports "
                          f"{node.module}.{a.name}" for a in node.names
                          if a.name.startswith("_") and not a.name.startswith("__")]
    assert not users, "\n".join(users)


def test_gui_uses_full_qt_enum_names_and_no_int_of_an_enum():
    """PySide6 (FreeCAD 1.1's Qt 6) accepts short enum names (QDialogButtonBox.Ok) only in
    its forgiveness mode and refuses int() of its flags."""
    import re

    short = re.compile(r"\b(QtCore\.Qt|QtWidgets\.Q[A-Za-z]+)\.([A-Z][A-Za-z]+)\b(?!\.|\()")
    full_scopes = {"StandardButton", "LineWrapMode", "DockWidgetArea", "ItemFlag",
                   "ItemDataRole"}
    found = []
    for path in sorted((PACKAGE / "gui").glob("*.py")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            for match in short.finditer(line):
                if match.group(2) not in full_scopes:
                    found.append(f"{path.name}:{number}: {match.group(0)}")
            if re.search(r"\bint\((QtCore|QtWidgets)\.", line):
                found.append(f"{path.name}:{number}: int() of a Qt enum")
    assert not found, "\n".join(found)
