"""The tool library tab's actions without Qt: list, edit, add, duplicate, delete, import and
export, each saved at once into the user library. Errors are ProcessError messages that the
tab shows as validation messages.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from freecad_conformal.errors import ProcessError
from freecad_conformal.process.library import ToolLibrary
from freecad_conformal.process.tools import Tool


@dataclass(frozen=True)
class ToolRow:
    """What the list shows for one tool."""

    id: str
    name: str
    kind: str
    diameter: float
    max_tilt_deg: float
    origin: str


@dataclass(frozen=True)
class FormFields:
    """The form's fields: they override the same keys of the JSON text when applied."""

    id: str
    name: str
    diameter: float
    max_tilt_deg: float


class ToolSession:
    """A loaded library and the edits made to it (saved after every change)."""

    def __init__(self, library: ToolLibrary) -> None:
        self.library = library

    @classmethod
    def load(cls, user_dir: Path | None = None) -> "ToolSession":
        return cls(ToolLibrary.load(user_dir=user_dir))

    def rows(self) -> list[ToolRow]:
        return [ToolRow(t.id, t.name, t.kind, t.diameter, math.degrees(t.max_tilt),
                        self.library.origin(t.id)) for t in self.library]

    def tool_json(self, tool_id: str) -> str:
        return json.dumps(self.library.get(tool_id).to_dict(), indent=2)

    def parse(self, json_text: str, fields: FormFields | None = None) -> Tool:
        """The tool described by the JSON text with the form's fields applied; checked."""
        try:
            data = json.loads(json_text)
        except json.JSONDecodeError as exc:
            raise ProcessError(f"tool JSON, line {exc.lineno} column {exc.colno}: {exc.msg}") from None
        if not isinstance(data, dict):
            raise ProcessError("tool JSON must be one object {...}")
        if fields is not None:
            data.update(id=fields.id.strip(), name=fields.name.strip(), diameter=fields.diameter,
                        max_tilt_deg=fields.max_tilt_deg)
        return Tool.from_dict(data, "edited in the tool library panel")

    def apply(self, original_id: str | None, json_text: str,
              fields: FormFields | None = None) -> Tool:
        """Store the edited tool: same id replaces it, a new id adds a tool (renaming a user
        tool removes the old id). Saved into the user library."""
        tool = self.parse(json_text, fields)
        if original_id and tool.id == original_id:
            self.library.set(tool)
        else:
            self.library.add(tool)
            if original_id and self.library.origin(original_id) == "user":
                self.library.remove(original_id)
        self.library.save()
        return tool

    def unused_id(self, base: str) -> str:
        """`base`_copy, `base`_copy2, ... whichever is free."""
        candidate, number = f"{base}_copy", 1
        while candidate in self.library:
            number += 1
            candidate = f"{base}_copy{number}"
        return candidate

    def new_tool(self, template_id: str) -> Tool:
        """A new user tool copied from `template_id` under a free id."""
        tool = self.library.duplicate(template_id, self.unused_id(template_id),
                                      name=f"New tool from {template_id}")
        self.library.save()
        return tool

    def duplicate(self, tool_id: str) -> Tool:
        tool = self.library.duplicate(tool_id, self.unused_id(tool_id))
        self.library.save()
        return tool

    def delete(self, tool_id: str) -> str:
        """Remove a user tool (an override gives the default back); returns what happened."""
        self.library.remove(tool_id)
        self.library.save()
        if tool_id in self.library:
            return f"removed your changes to {tool_id}: the shipped default is back"
        return f"deleted {tool_id}"

    def import_file(self, path: str | Path, replace: bool = False) -> list[str]:
        ids = self.library.import_file(path, replace=replace)
        self.library.save()
        return ids

    def export(self, path: str | Path, tool_ids: list[str] | None = None) -> None:
        self.library.export(path, tool_ids)
