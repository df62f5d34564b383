"""View providers of the Analysis and Decomposition objects: the centroidal axis drawn as a
polyline over the shape with its C1 break links marked, splitting faces highlighted, and
sub-parts coloured. The overlay is one small Coin group under the object's root node."""
from __future__ import annotations

from freecad_conformal.gui.colours import set_face_colours, set_shape_colour
from freecad_conformal.gui.icons import icon
from freecad_conformal.gui.path_display import PALETTE
from freecad_conformal.objects.properties import StoredState, add_properties

AXIS_COLOUR = (0.05, 0.05, 0.05)
BREAK_COLOUR = (0.90, 0.05, 0.05)
#: Splitting faces: red, half transparent, so the body shows through.
SPLIT_FACE_COLOUR = (0.90, 0.15, 0.15)
SPLIT_FACE_TRANSPARENCY = 40
AXIS_DATA = {"AxisPoints", "AxisLinks", "BreakLinks"}
VIEW_PROPERTIES = [("App::PropertyBool", "ShowAxis", "Display", "Draw the centroidal axis", True)]


class AxisOverlay:
    """Axis links as lines, break links thicker in red with markers at their ends."""

    def __init__(self, root) -> None:
        from pivy import coin

        self.switch = coin.SoSwitch()
        group = coin.SoSeparator()
        self.coords = coin.SoCoordinate3()
        group.addChild(self.coords)
        self.links = self._lines(group, AXIS_COLOUR, 2.0)
        self.breaks = self._lines(group, BREAK_COLOUR, 5.0)
        marker_colour = coin.SoBaseColor()
        marker_colour.rgb.setValue(*BREAK_COLOUR)
        self.markers = coin.SoMarkerSet()
        self.markers.markerIndex = coin.SoMarkerSet.CIRCLE_FILLED_9_9
        group.addChild(marker_colour)
        group.addChild(self.markers)
        self.switch.addChild(group)
        self.switch.whichChild = coin.SO_SWITCH_ALL
        root.addChild(self.switch)

    @staticmethod
    def _lines(group, colour, width):
        from pivy import coin

        style, base, lines = coin.SoDrawStyle(), coin.SoBaseColor(), coin.SoIndexedLineSet()
        style.lineWidth = width
        base.rgb.setValue(*colour)
        for node in (style, base, lines):
            group.addChild(node)
        return lines

    def update(self, obj, visible: bool) -> None:
        from pivy import coin

        points = [(p.x, p.y, p.z) for p in obj.AxisPoints]
        self.coords.point.setNum(0)
        self.coords.point.setValues(0, len(points), points)
        for node, pairs in ((self.links, obj.AxisLinks), (self.breaks, obj.BreakLinks)):
            index = []
            for k in range(0, len(pairs) - 1, 2):
                index += [pairs[k], pairs[k + 1], -1]
            node.coordIndex.setNum(0)
            node.coordIndex.setValues(0, len(index), index)
        ends = sorted(set(obj.BreakLinks))
        self.markers.numPoints = len(ends)
        self.markers.startIndex = 0
        if ends:   # markers draw coordinates in order: put the break ends first
            self.coords.point.setValues(len(points), len(ends), [points[i] for i in ends])
            self.markers.startIndex = len(points)
        self.switch.whichChild = coin.SO_SWITCH_ALL if visible else coin.SO_SWITCH_NONE


class _AxisViewProvider(StoredState):
    ICON = "Conformal"

    def __init__(self, vobj) -> None:
        vobj.Proxy = self
        add_properties(vobj, VIEW_PROPERTIES)

    def attach(self, vobj) -> None:
        add_properties(vobj, VIEW_PROPERTIES)
        self.Object = vobj.Object
        self.overlay = AxisOverlay(vobj.RootNode)
        self._refresh(vobj)

    def _refresh(self, vobj) -> None:
        # the overlay hangs under the root node, outside FreeCAD's display-mode switch, so
        # it follows the object's visibility here
        if getattr(self, "overlay", None) is not None and "ShowAxis" in vobj.PropertiesList:
            self.overlay.update(vobj.Object, vobj.ShowAxis and vobj.Visibility)

    def updateData(self, obj, prop: str) -> None:  # noqa: N802
        if prop in AXIS_DATA:
            self._refresh(obj.ViewObject)

    def onChanged(self, vobj, prop: str) -> None:  # noqa: N802
        if prop in ("ShowAxis", "Visibility"):
            self._refresh(vobj)

    def getIcon(self) -> str:  # noqa: N802
        return icon(self.ICON)


class ViewProviderAnalysis(_AxisViewProvider):
    """Splitting faces in translucent red with the axis over them."""

    ICON = "Conformal_Analyse"

    def __init__(self, vobj) -> None:
        super().__init__(vobj)
        set_shape_colour(vobj, SPLIT_FACE_COLOUR)
        vobj.Transparency = SPLIT_FACE_TRANSPARENCY


class ViewProviderDecomposition(_AxisViewProvider):
    """Sub-parts in palette colours (one per sub-part) with the axis over them."""

    ICON = "Conformal_Decompose"

    def updateData(self, obj, prop: str) -> None:  # noqa: N802
        super().updateData(obj, prop)
        if prop == "Shape":
            # Part's own view provider resets the face colours after a shape change:
            # colour once the event loop has run that
            from freecad_conformal.gui.qt import QtCore

            QtCore.QTimer.singleShot(0, lambda: self.colour_subparts(obj))

    @staticmethod
    def colour_subparts(obj) -> None:
        """One palette colour per sub-part solid; a face two sub-parts share (their
        splitting face) takes the first one's colour."""
        shape = obj.Shape
        solids = shape.Solids
        colours = []
        for face in shape.Faces:
            owner = next((k for k, solid in enumerate(solids)
                          if any(face.isSame(other) for other in solid.Faces)), 0)
            r, g, b = PALETTE[owner % len(PALETTE)]
            colours.append((float(r), float(g), float(b)))
        if colours:
            set_face_colours(obj.ViewObject, colours)
