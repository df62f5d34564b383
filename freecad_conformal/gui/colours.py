"""Face colours through the property the running FreeCAD has: ShapeAppearance (a material
per face) on 1.x, where ShapeColor and DiffuseColor remain only as compatibility
attributes, and ShapeColor / DiffuseColor on 0.20."""
from __future__ import annotations

from typing import Sequence

Colour = tuple[float, float, float]


def has_appearance(vobj) -> bool:
    return "ShapeAppearance" in vobj.PropertiesList


def set_shape_colour(vobj, colour: Colour) -> None:
    """One diffuse colour for the whole shape."""
    if has_appearance(vobj):
        vobj.ShapeAppearance = [_material(colour)]
    else:
        vobj.ShapeColor = tuple(float(c) for c in colour)


def set_face_colours(vobj, colours: Sequence[Colour]) -> None:
    """A diffuse colour per face, in the shape's face order."""
    if has_appearance(vobj):
        vobj.ShapeAppearance = [_material(c) for c in colours]
    else:
        vobj.DiffuseColor = [(float(r), float(g), float(b), 0.0) for r, g, b in colours]


def face_colours(vobj) -> list[Colour]:
    """The diffuse colour of every face as set (for checks and tests)."""
    if has_appearance(vobj):
        return [tuple(round(float(c), 6) for c in m.DiffuseColor[:3]) for m in vobj.ShapeAppearance]
    return [tuple(round(float(c), 6) for c in colour[:3]) for colour in vobj.DiffuseColor]


def _material(colour: Colour):
    import FreeCAD

    material = FreeCAD.Material()
    material.DiffuseColor = tuple(float(c) for c in colour)
    return material
