"""View providers: toolpaths as one Coin3D indexed line set (per-move colours, travel dimmed
or hidden, optional tool-axis ticks), sections with the default Part display.

One node set per object, whatever the number of points: 100,000 poses are one
SoCoordinate3, one SoMaterial with one colour per move and one SoIndexedLineSet.
"""
from __future__ import annotations

import FreeCAD

from freecad_conformal.gui.icons import icon
from freecad_conformal.gui.path_display import PLATFORM_COLOUR
from freecad_conformal.objects.properties import StoredState, add_properties

VIEW_GROUP = "Display"
TOOLPATH_VIEW_PROPERTIES = [
    ("App::PropertyEnumeration", "ColourBy", VIEW_GROUP, "Colour moves by sub-part, tool or kind",
     ("SubPart", "Tool", "Kind")),
    ("App::PropertyBool", "ShowTravel", VIEW_GROUP, "Draw travel moves (dimmed)", True),
    ("App::PropertyBool", "ShowToolAxes", VIEW_GROUP, "Draw tool-axis ticks", False),
    ("App::PropertyInteger", "AxisEvery", VIEW_GROUP, "A tick at every n-th pose", 50),
    ("App::PropertyLength", "AxisLength", VIEW_GROUP, "Length of a tool-axis tick", 5.0),
    ("App::PropertyFloat", "PathLineWidth", VIEW_GROUP, "Line width in pixels", 2.0),
    ("App::PropertyEnumeration", "Frame", VIEW_GROUP,
     "Draw a job's paths on the part as modelled, or where the machine builds them",
     ("Part", "Machine")),
    ("App::PropertyBool", "ShowPlatform", VIEW_GROUP, "Draw the platform under the job", True),
]
REDRAW_PROPERTIES = {"ColourBy", "ShowTravel", "ShowToolAxes", "AxisEvery", "AxisLength",
                     "PathLineWidth", "Frame", "ShowPlatform"}
DATA_PROPERTIES = {"ToolpathFile", "SegmentSubparts", "SupportSegments", "PartFrames"}
#: Colour of the tool-axis ticks (dark blue-grey, distinct from every path colour).
AXIS_COLOUR = (0.20, 0.25, 0.35)


#: Section wires are drawn in orange, thicker than body edges, to stand out on the body.
SECTION_LINE_COLOUR = (0.93, 0.45, 0.10)
SECTION_LINE_WIDTH = 2.0


class ViewProviderSections(StoredState):
    """Sections keep the Part display (wires) in their own colour; the icon is ours."""

    def __init__(self, vobj) -> None:
        vobj.Proxy = self
        vobj.LineColor = SECTION_LINE_COLOUR
        vobj.LineWidth = SECTION_LINE_WIDTH

    def attach(self, vobj) -> None:
        self.Object = vobj.Object

    def getIcon(self) -> str:  # noqa: N802 - FreeCAD's name
        return icon("Conformal_Sections")


class ViewProviderToolpath(StoredState):
    """Draws the toolpath stored in obj.ToolpathFile."""

    def __init__(self, vobj) -> None:
        vobj.Proxy = self
        add_properties(vobj, TOOLPATH_VIEW_PROPERTIES)

    def attach(self, vobj) -> None:
        from pivy import coin

        add_properties(vobj, TOOLPATH_VIEW_PROPERTIES)   # restored files from older versions
        self.Object = vobj.Object
        self.stats = {}
        self.root = coin.SoSeparator()
        self.style = coin.SoDrawStyle()
        self.coords = coin.SoCoordinate3()
        self.material = coin.SoMaterial()
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_PART
        self.lines = coin.SoIndexedLineSet()
        self.axes_switch = coin.SoSwitch()
        axes_group = coin.SoSeparator()
        axes_binding = coin.SoMaterialBinding()   # one colour, not the path's per-part ones
        axes_binding.value = coin.SoMaterialBinding.OVERALL
        axes_colour = coin.SoBaseColor()
        axes_colour.rgb.setValue(*AXIS_COLOUR)
        self.axes_coords = coin.SoCoordinate3()
        self.axes_lines = coin.SoLineSet()
        for node in (axes_binding, axes_colour, self.axes_coords, self.axes_lines):
            axes_group.addChild(node)
        self.axes_switch.addChild(axes_group)
        self.platform_switch = coin.SoSwitch()
        plate = coin.SoSeparator()
        plate_colour = coin.SoMaterial()
        plate_colour.diffuseColor.setValue(*PLATFORM_COLOUR)
        plate_colour.transparency.setValue(0.6)
        plate_binding = coin.SoMaterialBinding()
        plate_binding.value = coin.SoMaterialBinding.OVERALL
        self.platform_coords = coin.SoCoordinate3()
        self.plate_faces = coin.SoFaceSet()
        self.plate_faces.numVertices.setValue(4)
        for node in (plate_binding, plate_colour, self.platform_coords, self.plate_faces):
            plate.addChild(node)
        self.platform_switch.addChild(plate)
        for node in (self.style, self.coords, self.material, binding, self.lines, self.axes_switch,
                     self.platform_switch):
            self.root.addChild(node)
        vobj.addDisplayMode(self.root, "Path")
        self.redraw(vobj)

    def getDisplayModes(self, _vobj) -> list[str]:  # noqa: N802
        return ["Path"]

    def getDefaultDisplayMode(self) -> str:  # noqa: N802
        return "Path"

    def setDisplayMode(self, mode: str) -> str:  # noqa: N802
        return mode

    def getIcon(self) -> str:  # noqa: N802
        return icon("Conformal_Toolpath")

    def updateData(self, obj, prop: str) -> None:  # noqa: N802
        if prop in DATA_PROPERTIES and getattr(self, "root", None) is not None:
            self.redraw(obj.ViewObject)

    def onChanged(self, vobj, prop: str) -> None:  # noqa: N802
        if prop in REDRAW_PROPERTIES and getattr(self, "root", None) is not None:
            self.redraw(vobj)

    def redraw(self, vobj) -> None:
        """Fill the nodes from the stored toolpath; a bad file is reported, not raised."""
        from freecad_conformal.errors import ConformalError
        from freecad_conformal.objects.toolpath_feature import load_toolpath

        needed = ("ColourBy", "ShowTravel", "PathLineWidth", "Frame", "ShowPlatform")
        if not all(name in vobj.PropertiesList for name in needed):
            return  # still being set up
        try:
            toolpath = load_toolpath(vobj.Object)
        except ConformalError as exc:
            FreeCAD.Console.PrintError(f"{vobj.Object.Label}: cannot draw the toolpath: {exc}\n")
            toolpath = None
        self.style.lineWidth = vobj.PathLineWidth
        if toolpath is None or len(toolpath.points) < 2:
            self._clear()
            return
        self._fill(vobj, toolpath)

    def _clear(self) -> None:
        self.lines.coordIndex.setNum(0)
        self.coords.point.setNum(0)
        self.axes_switch.whichChild = -1
        self.platform_switch.whichChild = -1
        self.stats = {"vertices": 0, "moves": 0}

    def _fill(self, vobj, toolpath) -> None:
        from pivy import coin

        from dataclasses import replace

        from freecad_conformal.gui.path_display import (
            axis_ticks, frame_matrices, line_set, platform_plates, to_part_frame)
        from freecad_conformal.toolpath import KINDS

        obj = vobj.Object
        subparts = list(obj.SegmentSubparts)
        matrices: dict = {}
        if vobj.Frame == "Part" and "PartFrames" in obj.PropertiesList:
            matrices = frame_matrices(obj.PartFrameSubparts, obj.PartFrames)
        # a plate under each solid (its sub-parts share one motion onto the part), under
        # what is built: travels between solids would stretch it
        built = toolpath.kind[toolpath.segment_index] != KINDS.index("travel")
        if not built.any():
            built[:] = True
        plates = platform_plates(toolpath.points[built], toolpath.segment_index[built], subparts,
                                 matrices)
        if matrices:
            # the part as modelled: each sub-part's paths moved back from the machine frame
            toolpath = replace(
                toolpath,
                points=to_part_frame(toolpath.points, toolpath.segment_index, subparts, matrices),
                axes=to_part_frame(toolpath.axes, toolpath.segment_index, subparts, matrices,
                                   directions=True))
        shows_platform = vobj.ShowPlatform and "PartFrames" in obj.PropertiesList
        corners = [corner for plate in plates for corner in plate.tolist()]
        self.platform_coords.point.setValues(0, len(corners), corners)
        self.platform_coords.point.setNum(len(corners))
        self.plate_faces.numVertices.setValues(0, len(plates), [4] * len(plates))
        self.plate_faces.numVertices.setNum(len(plates))
        self.platform_switch.whichChild = coin.SO_SWITCH_ALL if shows_platform else coin.SO_SWITCH_NONE
        support = (list(obj.SupportSegments) if "SupportSegments" in obj.PropertiesList
                   else [])        # a document saved before support was drawn apart
        data = line_set(toolpath, vobj.ColourBy, subparts, vobj.ShowTravel, support)
        self.lines.coordIndex.setNum(0)
        self.coords.point.setValues(0, len(data.points), data.points.tolist())
        self.coords.point.setNum(len(data.points))
        self.material.diffuseColor.setValues(0, len(data.part_colours), data.part_colours.tolist())
        self.material.diffuseColor.setNum(len(data.part_colours))
        self.lines.coordIndex.setValues(0, len(data.coord_index), data.coord_index.tolist())
        ticks = axis_ticks(toolpath, vobj.AxisEvery, vobj.AxisLength.Value) \
            if vobj.ShowToolAxes else None
        if ticks is not None and len(ticks):
            self.axes_coords.point.setValues(0, len(ticks), ticks.tolist())
            self.axes_coords.point.setNum(len(ticks))
            self.axes_lines.numVertices.setValues(0, len(ticks) // 2, [2] * (len(ticks) // 2))
            self.axes_lines.numVertices.setNum(len(ticks) // 2)
            self.axes_switch.whichChild = coin.SO_SWITCH_ALL
        else:
            self.axes_switch.whichChild = coin.SO_SWITCH_NONE
        self.stats = {"vertices": len(data.points), "moves": data.moves,
                      "index_length": len(data.coord_index),
                      "axis_ticks": 0 if ticks is None else len(ticks) // 2}

    def scene_counts(self) -> dict:
        """Node counts under this view's root, by type (a test checks there is one line set)."""
        counts: dict = {}

        def walk(node):
            name = node.getTypeId().getName().__str__()
            counts[name] = counts.get(name, 0) + 1
            for k in range(node.getNumChildren() if hasattr(node, "getNumChildren") else 0):
                walk(node.getChild(k))
        walk(self.root)
        return counts


class ViewProviderProgram(StoredState):
    """Post and Verify objects: nothing to draw, an icon that says what they are (a Verify
    that failed shows a red cross) and the result in the tree's second column."""

    def __init__(self, vobj) -> None:
        vobj.Proxy = self

    def attach(self, vobj) -> None:
        self.Object = vobj.Object

    def getIcon(self) -> str:  # noqa: N802
        obj = getattr(self, "Object", None)
        if obj is not None and "Passed" in obj.PropertiesList:
            return icon("Conformal_Verify" if obj.Passed or not obj.Report else
                        "Conformal_VerifyFailed")
        return icon("Conformal_Post")

    def updateData(self, obj, prop: str) -> None:  # noqa: N802
        if prop == "Passed":
            obj.Label2 = "passed" if obj.Passed else ("failed" if obj.Report else "")
        elif prop == "EstimatedSeconds" and "BlockCount" in obj.PropertiesList:
            from freecad_conformal.jobs.report import format_duration

            obj.Label2 = f"{obj.BlockCount} blocks, {format_duration(obj.EstimatedSeconds)}"

    def onChanged(self, vobj, prop: str) -> None:  # noqa: N802
        return None
