"""Toolpath document object: a neutral toolpath (freecad_conformal.toolpath) kept inside the
.FCStd as its .npz file, with a sub-part index per segment for colouring. The Job object
(job_feature.py) is a toolpath object whose toolpath comes from the planner."""
from __future__ import annotations

import os
import tempfile
from typing import Sequence


from freecad_conformal.objects.properties import StoredState, add_properties

GROUP = "Toolpath"
TOOLPATH_PROPERTIES = [
    ("App::PropertyFileIncluded", "ToolpathFile", GROUP, "Neutral toolpath (.npz) kept in the document", None),
    ("App::PropertyIntegerList", "SegmentSubparts", GROUP, "Sub-part index of every segment", None),
    ("App::PropertyIntegerList", "SupportSegments", GROUP,
     "Segments that print support (drawn grey: it breaks away after printing)", None),
    ("App::PropertyInteger", "PointCount", GROUP, "Tool poses in the toolpath", 0),
    ("App::PropertyInteger", "SegmentCount", GROUP, "Segments in the toolpath", 0),
    ("App::PropertyLength", "PathLength", GROUP, "Length of all moves", 0.0),
]
TOOLPATH_OUTPUTS = ("PointCount", "SegmentCount", "PathLength", "SegmentSubparts",
                    "SupportSegments")


class ToolpathFeature(StoredState):
    """Proxy of an App::FeaturePython that only holds a toolpath (imported or computed)."""

    def __init__(self, obj) -> None:
        obj.Proxy = self
        self.setup(obj)

    def setup(self, obj) -> None:
        add_properties(obj, TOOLPATH_PROPERTIES, read_only=TOOLPATH_OUTPUTS)

    def onDocumentRestored(self, obj) -> None:  # noqa: N802 - FreeCAD's name
        self.setup(obj)

    def execute(self, obj) -> None:
        """Re-read the stored toolpath (validates it; nothing to compute)."""
        load_toolpath(obj)


def store_toolpath(obj, toolpath, segment_subparts: Sequence[int] | None = None,
                   support_segments: Sequence[int] = ()) -> None:
    """Put `toolpath` into obj.ToolpathFile (copied into the document) and its statistics,
    with each segment's sub-part and the segments that print support."""
    handle, path = tempfile.mkstemp(suffix=".npz", prefix=f"{obj.Name}_")
    os.close(handle)
    try:
        toolpath.save(path)
        obj.ToolpathFile = path
    finally:
        if os.path.exists(path):
            os.remove(path)
    count = toolpath.segment_count
    subparts = list(segment_subparts) if segment_subparts is not None else [0] * count
    if len(subparts) != count:
        raise ValueError(f"{len(subparts)} sub-part indices for {count} segments")
    if any(not 0 <= int(s) < count for s in support_segments):
        raise ValueError(f"support segments outside the toolpath's {count} segments")
    obj.SegmentSubparts = [int(s) for s in subparts]
    obj.SupportSegments = [int(s) for s in support_segments]
    obj.PointCount = int(len(toolpath.points))
    obj.SegmentCount = int(count)
    obj.PathLength = float(toolpath.move_lengths().sum())


def toolpath_from_bytes(data: bytes):
    """The toolpath of .npz bytes (Toolpath.to_bytes): how toolpaths come back from a worker."""
    from freecad_conformal.toolpath import Toolpath

    handle, path = tempfile.mkstemp(suffix=".npz", prefix="conformal_")
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
        return Toolpath.load(path)
    finally:
        os.remove(path)


def toolpath_bytes(obj) -> bytes:
    """The stored .npz of obj.ToolpathFile as bytes (how a toolpath goes to a worker)."""
    from freecad_conformal.errors import PostError

    path = obj.ToolpathFile if "ToolpathFile" in obj.PropertiesList else ""
    if not path or not os.path.isfile(path):
        raise PostError(f"{obj.Label} holds no toolpath yet (recompute it)")
    with open(path, "rb") as handle:
        return handle.read()


def load_toolpath(obj):
    """The toolpath stored in obj.ToolpathFile, or None when none is stored yet."""
    from freecad_conformal.toolpath import Toolpath

    path = obj.ToolpathFile
    if not path or not os.path.isfile(path):
        return None
    return Toolpath.load(path)


def create_toolpath(doc, toolpath, segment_subparts: Sequence[int] | None = None,
                    name: str = "Toolpath"):
    """A Toolpath object holding `toolpath` (gui/views.show gives it its view provider)."""
    obj = doc.addObject("App::FeaturePython", name)
    ToolpathFeature(obj)
    store_toolpath(obj, toolpath, segment_subparts)
    return obj
