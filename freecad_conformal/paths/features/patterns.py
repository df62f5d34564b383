"""Patterns on faces: a planar outline wrapped onto a face, filled, stacked along the normal.

The pattern plane (x, y in mm, origin at the pattern's placement point) is mapped onto the
face without stretching where the surface allows it:

- cylinder: exact, x is arc length round the axis and y the axial distance (developable);
- cone: exact, through the cone's development (slant distance and unrolled angle);
- sphere: azimuthal equidistant about the placement point: distances from that point and
  directions there are exact, circles of radius ρ shrink by sin(ρ/R)/(ρ/R) (a sphere cannot
  be flattened; this is the least radial distortion);
- any other face: through its parameterisation with the metric taken into account: x is arc
  length along the v = v_c iso-curve and y arc length along the u iso-curve from there
  (exact on developable faces parameterised by arc length, first-order elsewhere). The
  distortion is measured by `distortion` (mapped length / planar length of the fill lines).

Every mapped point must lie on the face, else PlanError: the pattern is larger than its face.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from freecad_conformal.errors import PlanError
from freecad_conformal.geometry.faces import face_kind, normals_at, parameters_of, points_at
from freecad_conformal.paths.features.fill import contours, zigzag
from freecad_conformal.paths.features.moves import approach, retract, travel
from freecad_conformal.toolpath import ToolpathBuilder
from freecad_conformal.tolerances import COINCIDENT_POINTS, ROUNDING_SLACK

#: Fill lines are resampled at this step (mm) before mapping, so the mapped polyline follows
#: the surface: on R >= 2 mm the chord of 0.2 mm deviates < 0.0025 mm.
MAP_STEP = 0.2

#: Samples per direction of the arc-length tables of the general mapping.
ARC_SAMPLES = 257


def densify(line: np.ndarray, step: float = MAP_STEP) -> np.ndarray:
    """Insert points so no piece of the polyline is longer than `step`."""
    out = [line[:1]]
    for a, b in zip(line[:-1], line[1:]):
        n = max(int(math.ceil(np.linalg.norm(b - a) / step)), 1)
        out.append(a + np.outer(np.arange(1, n + 1) / n, b - a))
    return np.concatenate(out)


@dataclass
class FaceMapping:
    """Maps pattern-plane points (N, 2) to face parameters (N, 2) by the face's kind."""

    face: object
    centre: tuple[float, float]          # (u, v) of the pattern origin
    kind: str = ""

    def __post_init__(self) -> None:
        self.kind = face_kind(self.face)
        s = self.face.Surface
        uc, vc = self.centre
        # x runs along +u unless that mirrors the pattern seen from outside the material
        # (a reversed face such as a bore): then along −u.
        cross = np.cross(np.array(tuple(s.getDN(uc, vc, 1, 0))), np.array(tuple(s.getDN(uc, vc, 0, 1))))
        self.flip = 1.0 if cross @ np.array(tuple(self.face.normalAt(uc, vc))) >= 0 else -1.0
        if self.kind in ("cylinder", "sphere", "cone"):
            self.radius = float(s.Radius)
        if self.kind == "sphere":
            self._c = np.array(tuple(self.face.valueAt(uc, vc))) - np.array(tuple(s.Center))
            self._c /= np.linalg.norm(self._c)
            east = np.array(tuple(s.getDN(uc, vc, 1, 0)))
            self._east = east / np.linalg.norm(east)
            self._north = np.cross(self._c, self._east)
        if self.kind not in ("cylinder", "sphere", "cone"):
            self._tables()

    def check_wrap(self, width: float, height: float, what: str) -> None:
        """PlanError if the pattern would wrap onto itself round a closed face."""
        if self.kind == "cylinder" and width >= 2 * math.pi * self.radius:
            limit = 2 * math.pi * self.radius
        elif self.kind == "sphere" and math.hypot(width, height) / 2 >= math.pi * self.radius:
            limit = 2 * math.pi * self.radius
        else:
            return
        raise PlanError(f"{what}: the pattern ({width:.3g} x {height:.3g} mm) is larger than its "
                        f"face: it would wrap onto itself ({limit:.3g} mm round)")

    def to_uv(self, xy: np.ndarray) -> np.ndarray:
        xy = np.atleast_2d(np.asarray(xy, dtype=float)) * np.array([self.flip, 1.0])
        uc, vc = self.centre
        if self.kind == "cylinder":
            return np.column_stack((uc + xy[:, 0] / self.radius, vc + xy[:, 1]))
        if self.kind == "cone":
            return self._cone(xy)
        if self.kind == "sphere":
            return self._sphere(xy)
        return self._general(xy)

    def _cone(self, xy: np.ndarray) -> np.ndarray:
        alpha = float(self.face.Surface.SemiAngle)
        uc, vc = self.centre
        apex_distance = self.radius / math.sin(alpha) + vc        # slant distance of the centre
        # development: a sector, centre point at (0, −apex_distance) from the apex image
        px, py = xy[:, 0], xy[:, 1] + apex_distance
        slant = np.hypot(px, py)
        psi = np.arctan2(px, py)
        return np.column_stack((uc + psi / math.sin(alpha), slant - self.radius / math.sin(alpha)))

    def _sphere(self, xy: np.ndarray) -> np.ndarray:
        rho = np.hypot(xy[:, 0], xy[:, 1]) / self.radius
        direction = (np.outer(xy[:, 0], self._east) + np.outer(xy[:, 1], self._north))
        norm = np.linalg.norm(direction, axis=1)
        direction = np.divide(direction, norm[:, None], out=np.zeros_like(direction), where=norm[:, None] > 0)
        unit = np.outer(np.cos(rho), self._c) + np.sin(rho)[:, None] * direction
        centre = np.array(tuple(self.face.Surface.Center))
        return parameters_of(self.face, centre + self.radius * unit)

    def _tables(self) -> None:
        """Arc length along u at v_c, and along v at each sampled u."""
        u0, u1, v0, v1 = self.face.ParameterRange
        uc, vc = self.centre
        self._us = np.linspace(u0, u1, ARC_SAMPLES)
        self._vs = np.linspace(v0, v1, ARC_SAMPLES)
        row = points_at(self.face, np.column_stack((self._us, np.full(ARC_SAMPLES, vc))))
        arc = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(row, axis=0), axis=1))))
        self._arc_u = arc - np.interp(uc, self._us, arc)
        grid = points_at(self.face, np.array([(u, v) for u in self._us for v in self._vs]))
        grid = grid.reshape(ARC_SAMPLES, ARC_SAMPLES, 3)
        arc_v = np.concatenate((np.zeros((ARC_SAMPLES, 1)), np.cumsum(
            np.linalg.norm(np.diff(grid, axis=1), axis=2), axis=1)), axis=1)
        self._arc_v = arc_v - np.array([np.interp(vc, self._vs, r) for r in arc_v])[:, None]

    def _general(self, xy: np.ndarray) -> np.ndarray:
        if np.any(xy[:, 0] < self._arc_u[0]) or np.any(xy[:, 0] > self._arc_u[-1]):
            raise PlanError("pattern is wider than its face along u")
        u = np.interp(xy[:, 0], self._arc_u, self._us)
        col = np.interp(u, self._us, np.arange(ARC_SAMPLES))
        lo = np.clip(np.floor(col).astype(int), 0, ARC_SAMPLES - 2)
        w = col - lo
        v = np.empty(len(xy))
        for k, (row, weight, y) in enumerate(zip(lo, w, xy[:, 1])):
            table = (1 - weight) * self._arc_v[row] + weight * self._arc_v[row + 1]
            if y < table[0] or y > table[-1]:
                raise PlanError("pattern is taller than its face along v")
            v[k] = np.interp(y, table, self._vs)
        return np.column_stack((u, v))


def check_on_face(face, uv: np.ndarray, what: str, size: tuple[float, float]) -> None:
    """PlanError if any mapped point falls off the face (outside its trimmed domain)."""
    u0, u1, v0, v1 = face.ParameterRange
    periodic = face.Surface.isUPeriodic() and (u1 - u0) >= 2 * math.pi - ROUNDING_SLACK
    for u, v in uv:
        if periodic:
            u = u0 + (u - u0) % (2 * math.pi)
        if not (u0 - ROUNDING_SLACK <= u <= u1 + ROUNDING_SLACK
                and v0 - ROUNDING_SLACK <= v <= v1 + ROUNDING_SLACK) or \
                not face.isPartOfDomain(float(u), float(v)):
            raise PlanError(f"{what}: the pattern ({size[0]:.3g} x {size[1]:.3g} mm) is larger "
                            "than its face: it runs off the face's edge")


def distortion(face, mapping: FaceMapping, lines: list[np.ndarray]) -> float:
    """Largest relative length error |mapped / planar − 1| over the pieces of `lines`."""
    worst = 0.0
    for line in lines:
        fine = densify(line)
        xyz = points_at(face, mapping.to_uv(fine))
        planar = np.linalg.norm(np.diff(fine, axis=0), axis=1)
        mapped = np.linalg.norm(np.diff(xyz, axis=0), axis=1)
        keep = planar > COINCIDENT_POINTS
        worst = max(worst, float(np.max(np.abs(mapped[keep] / planar[keep] - 1.0))))
    return worst


@dataclass
class PatternPath:
    points: np.ndarray
    axes: np.ndarray
    layer: int


def pattern_paths(face, region, width: float, height: float, layer: float,
                  centre: tuple[float, float] | None = None, fill: str = "contours",
                  angle: float = 0.0, what: str = "pattern") -> tuple[list[PatternPath], FaceMapping]:
    """Fill the planar `region` (shapely, centred on its bounding box middle), wrap it onto
    `face` about `centre` (u, v; default the middle of the face's parameter box) and stack it
    `height` mm along the normal in `layer` mm layers."""
    if not (width > 0 and height > 0 and layer > 0):
        raise PlanError(f"{what}: width, height and layer must be > 0 mm")
    x0, y0, x1, y1 = region.bounds
    from shapely import affinity
    region = affinity.translate(region, -(x0 + x1) / 2, -(y0 + y1) / 2)
    u0, u1, v0, v1 = face.ParameterRange
    centre = centre or (0.5 * (u0 + u1), 0.5 * (v0 + v1))
    try:
        mapping = FaceMapping(face, centre)
        mapping.check_wrap(x1 - x0, y1 - y0, what)
        outline = [np.asarray(region.envelope.exterior.coords)]
        check_on_face(face, mapping.to_uv(densify(outline[0], width)), what, (x1 - x0, y1 - y0))
    except PlanError as exc:
        raise PlanError(f"{what}: {exc}" if not str(exc).startswith(what) else str(exc)) from None
    if fill == "contours":
        lines = contours(region, width, what=what)
    elif fill == "zigzag":
        lines = zigzag(region, width, angle, what=what)
    else:
        raise PlanError(f"{what}: fill must be 'contours' or 'zigzag', got {fill!r}")
    count = max(int(math.ceil(height / layer - ROUNDING_SLACK)), 1)
    out = []
    for line in lines:
        uv = mapping.to_uv(densify(line))
        base, normals = points_at(face, uv), normals_at(face, uv)
        for k in range(count):
            out.append(PatternPath(base + (k + 0.5) * layer * normals, normals, k))
    out.sort(key=lambda p: p.layer)
    return out, mapping


def patterns_toolpath(paths: list[PatternPath], feed: float, tool_number: int = 0,
                      power: float = 1.0, travel_feed: float = 600.0, lift: float = 2.0,
                      builder: ToolpathBuilder | None = None, face=None,
                      energy_per_mm: float = 0.0) -> ToolpathBuilder:
    """Come down the normal onto the first path, cure each path with the light on, and travel
    between paths `lift` mm above the face (moves.travel: along the offset face, not a chord
    through what is built; a straight move when no face is given); retract at the end."""
    builder = builder or ToolpathBuilder(part="pattern", material="UV resin")
    previous = None
    for path in paths:
        start, axis = path.points[0], path.axes[0]
        if previous is None:
            approach(builder, start, axis, lift, travel_feed, tool_number)
        elif face is not None:
            travel(builder, face, previous.points[-1], previous.axes[-1], start, axis, lift,
                   travel_feed, tool_number)
        else:
            builder.add_segment([previous.points[-1] + lift * previous.axes[-1],
                                 start + lift * axis, start], axes=axis, kind="travel",
                                feed=travel_feed, tool=tool_number)
        builder.event("light_on", power=power)
        builder.add_segment(path.points, path.axes, kind="cure", feed=feed, tool=tool_number,
                            flow=energy_per_mm)
        builder.event("light_off")
        previous = path
    if previous is not None:
        retract(builder, previous.points[-1], previous.axes[-1], lift, travel_feed, tool_number)
    return builder
