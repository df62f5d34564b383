"""The tool library store: shipped defaults plus the user's own tools, as JSON files.

Every file has the form `{"format": "conformal-tools", "version": 1, "tools": [...]}` (one
tool per file in the library folders, several in an export). The user library lives in
FreeCAD's user data folder (`<user data>/Conformal/tools`); a user tool with the id of a
shipped default shadows it, which is how a default is customised (e.g. by a DOE setting).
"""
from __future__ import annotations

import importlib
import json
import os
from pathlib import Path
from typing import Iterable, Iterator

from freecad_conformal import RESOURCES
from freecad_conformal.errors import ProcessError
from freecad_conformal.fileio import write_text_atomic
from freecad_conformal.process import json_fields as schema
from freecad_conformal.process.tools import ID_PATTERN, Tool

FORMAT = "conformal-tools"
VERSION = 1
DEFAULT_TOOL_DIR = RESOURCES / "tools"
#: Environment variable that moves the user folder (tests, portable installs).
USER_DIR_ENV = "CONFORMAL_USER_DIR"


def user_data_dir() -> Path:
    """The Conformal user folder: $CONFORMAL_USER_DIR, else FreeCAD's user data folder when
    FreeCAD is importable, else ~/.local/share/FreeCAD/Conformal (FreeCAD's default place)."""
    override = os.environ.get(USER_DIR_ENV)
    if override:
        return Path(override).expanduser()
    try:
        freecad = importlib.import_module("FreeCAD")
        return Path(freecad.getUserAppDataDir()) / "Conformal"
    except (ImportError, AttributeError):
        return Path.home() / ".local" / "share" / "FreeCAD" / "Conformal"


def user_tool_dir() -> Path:
    return user_data_dir() / "tools"


def read_tool_file(path: str | os.PathLike) -> list[Tool]:
    """Read and check every tool of one file; duplicate ids inside the file are rejected."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ProcessError(f"cannot read tool file {path}: {exc.strerror or exc}") from exc
    except json.JSONDecodeError as exc:
        raise ProcessError(f"tool file {path} is not valid JSON: {exc}") from exc
    where = f"tool file {path.name}"
    schema.check_keys(data, ("format", "version", "tools"), where)
    if data.get("format") != FORMAT:
        raise ProcessError(f"{where}: 'format' must be {FORMAT!r}, got {data.get('format')!r}")
    version = schema.integer(data, "version", where, minimum=1)
    if version > VERSION:
        raise ProcessError(f"{where}: version {version} is newer than this Conformal reads "
                           f"({VERSION}); update the workbench")
    entries = data.get("tools")
    if not isinstance(entries, list) or not entries:
        raise ProcessError(f"{where}: 'tools' must be a non-empty list")
    tools = [Tool.from_dict(entry, path.name) for entry in entries]
    _reject_duplicates(tools, where)
    return tools


def tools_to_json(tools: Iterable[Tool]) -> str:
    return json.dumps({"format": FORMAT, "version": VERSION,
                       "tools": [t.to_dict() for t in tools]}, indent=2) + "\n"


def _reject_duplicates(tools: Iterable[Tool], where: str) -> None:
    seen: set[str] = set()
    for tool in tools:
        if tool.id in seen:
            raise ProcessError(f"{where}: duplicate tool id {tool.id!r}")
        seen.add(tool.id)


def _read_folder(folder: Path) -> dict[str, tuple[Tool, Path]]:
    """id -> (tool, file) for the *.json files of a folder; an id in two files is an error."""
    tools: dict[str, tuple[Tool, Path]] = {}
    if not folder.is_dir():
        return tools
    for path in sorted(folder.glob("*.json")):
        for tool in read_tool_file(path):
            if tool.id in tools:
                raise ProcessError(f"duplicate tool id {tool.id!r} in {folder}: "
                                   f"{tools[tool.id][1].name} and {path.name}")
            tools[tool.id] = (tool, path)
    return tools


class ToolLibrary:
    """Tools by id, each remembered as a shipped 'default' or a 'user' tool.

    Edits (add, remove, duplicate, set) change the library in memory; `save` writes the user
    tools, one file per tool, into the user folder (atomically) and deletes removed ones.
    """

    def __init__(self, default_dir: Path | None = DEFAULT_TOOL_DIR,
                 user_dir: Path | None = None) -> None:
        self.default_dir = Path(default_dir) if default_dir is not None else None
        self.user_dir = Path(user_dir) if user_dir is not None else user_tool_dir()
        self._tools: dict[str, Tool] = {}
        self._origin: dict[str, str] = {}
        #: user tools read from a file not named <id>.json are saved back to that file
        self._user_files: dict[str, Path] = {}

    @classmethod
    def load(cls, default_dir: Path | None = DEFAULT_TOOL_DIR,
             user_dir: Path | None = None) -> "ToolLibrary":
        library = cls(default_dir, user_dir)
        if library.default_dir is not None:
            for tool_id, (tool, _) in _read_folder(library.default_dir).items():
                library._tools[tool_id], library._origin[tool_id] = tool, "default"
        for tool_id, (tool, path) in _read_folder(library.user_dir).items():
            library._tools[tool_id], library._origin[tool_id] = tool, "user"
            library._user_files[tool_id] = path
        return library

    def __iter__(self) -> Iterator[Tool]:
        return iter(sorted(self._tools.values(), key=lambda t: t.id))

    def __len__(self) -> int:
        return len(self._tools)

    def __contains__(self, tool_id: object) -> bool:
        return tool_id in self._tools

    def ids(self) -> list[str]:
        return sorted(self._tools)

    def origin(self, tool_id: str) -> str:
        """'default' (shipped, unchanged) or 'user'."""
        self.get(tool_id)
        return self._origin[tool_id]

    def get(self, tool_id: str) -> Tool:
        try:
            return self._tools[tool_id]
        except KeyError:
            known = ", ".join(self.ids()) or "none"
            raise ProcessError(f"no tool {tool_id!r} in the library (known: {known})") from None

    def add(self, tool: Tool, replace: bool = False) -> None:
        """Add a checked user tool; an existing id is an error unless `replace`."""
        tool.validate()
        if tool.id in self._tools and not replace:
            raise ProcessError(f"tool id {tool.id!r} is already in the library "
                               f"({self._origin[tool.id]}); choose another id or replace it")
        self._tools[tool.id], self._origin[tool.id] = tool, "user"

    def set(self, tool: Tool) -> None:
        """Store an edited tool (a shipped default becomes a user override)."""
        self.get(tool.id)
        self.add(tool, replace=True)

    def remove(self, tool_id: str) -> Tool:
        """Remove a user tool; shipped defaults cannot be removed, only overridden."""
        tool = self.get(tool_id)
        if self._origin[tool_id] == "default":
            raise ProcessError(f"tool {tool_id!r} is a shipped default and cannot be removed")
        del self._tools[tool_id], self._origin[tool_id]
        if self.default_dir is not None:
            shipped = _read_folder(self.default_dir).get(tool_id)
            if shipped is not None:  # removing an override brings the default back
                self._tools[tool_id], self._origin[tool_id] = shipped[0], "default"
        return tool

    def duplicate(self, tool_id: str, new_id: str, name: str | None = None) -> Tool:
        """Copy a tool under a new id (and name) as a user tool; returns the copy."""
        if not ID_PATTERN.match(new_id):
            raise ProcessError(f"new tool id {new_id!r} must be lower-case letters, digits, "
                               "'_', '-' or '.'")
        clone = self.get(tool_id).copy()
        clone.id = new_id
        clone.name = name or f"{clone.name} (copy)"
        self.add(clone)
        return clone

    def validate(self) -> None:
        """Check every tool again (tools may have been edited in memory)."""
        for tool in self._tools.values():
            tool.validate()

    def save(self) -> list[Path]:
        """Write the user tools into the user folder; returns the files written.

        A tool read from a user file goes back to that file (with the other tools still in
        it); a new tool goes to `<id>.json`; a file left without tools is deleted.
        """
        self.validate()
        by_file: dict[Path, list[Tool]] = {path: [] for path in self._user_files.values()}
        for tool in self:
            if self._origin[tool.id] == "user":
                path = self._user_files.setdefault(tool.id, self.user_dir / f"{tool.id}.json")
                by_file.setdefault(path, []).append(tool)
        written = []
        for path, tools in sorted(by_file.items()):
            if tools:
                # the user tool folder is the library's own: made on first save
                path.parent.mkdir(parents=True, exist_ok=True)
                write_text_atomic(path, tools_to_json(tools))
                written.append(path)
            else:
                path.unlink(missing_ok=True)
        return written

    def export(self, path: str | os.PathLike, tool_ids: Iterable[str] | None = None) -> None:
        """Write the chosen tools (all by default) into one file."""
        ids = list(tool_ids) if tool_ids is not None else self.ids()
        write_text_atomic(path, tools_to_json(self.get(i) for i in ids))

    def import_file(self, path: str | os.PathLike, replace: bool = False) -> list[str]:
        """Add every tool of a file as user tools; all or nothing. Returns the ids added."""
        tools = read_tool_file(path)
        clashes = [t.id for t in tools if t.id in self._tools]
        if clashes and not replace:
            raise ProcessError(f"{Path(path).name}: tool id(s) {', '.join(clashes)} already in "
                               "the library; rename them or import with replace")
        for tool in tools:
            self.add(tool, replace=True)
        return [t.id for t in tools]
