"""Whether 3-D layers would spare a sub-part overhang, read before any is made.

A tilted stack (layers/tilted.py) costs three OCC cuts a layer, and prints slower than
planar layers (0.6-13 % on every tilted stack measured). It pays only where its planes,
turned along the bend, leave less of the surface overhanging than planar ones. That is
estimated on the sub-part's mesh: the overhang under planar layers that the normal a
following plane would take at its height (the drift of the planar sections' centroids
there) turns back within the limit. Overhang such a turn would create is not counted: the
estimate only has to tell a bend that spares overhang from one beside it, and a drift
read across a junction (a rod leaving its base plate) leans where no plane will.

Shares of the sub-part's overhang estimated spared: the pipe elbow 1.00, a bent bar 1.00
and a branch leaning 55° 1.00, whose 3-D layers then spared it (the elbow's support,
12,669 mm³ planar, is none under them); a straight rod leaning 55° off a plate 0.98 (the
chain makes no 3-D layer there, and the plan turns that part whole instead); the
connecting rod 0.05 (its overhang is the boss's underside, which its gently bent shank
cannot turn to: its 3-D layers took 5 s of planning to spare 1.4 % of the support) and a
rod leaning 30° under a flat cap 0.00.
"""
from __future__ import annotations

import math

import numpy as np

from freecad_conformal.decomposition.subparts import SubPart
from freecad_conformal.geometry.overhang import DEFAULT_OVERHANG_ANGLE, overhang_threshold
from freecad_conformal.layers.model import Layer
from freecad_conformal.layers.tilted import BEND_MAX_ANGLE, layer_centroids

#: The drift over this far (mm) on each side of a layer stands for the normal a following
#: plane takes there: the chain turns gradually (bisected within the thickness bounds), so
#: a shorter reach follows kinks the planes do not.
FOLLOW_REACH = 4.0

#: 3-D layers are made when they are estimated to spare at least this share of the
#: sub-part's overhang: below it their slower print and planning buy too little (the
#: connecting rod: 5 %; the bends that need them: 98-100 %).
TILT_SAVING = 0.25


def following_spares(subpart: SubPart, layers: list[Layer],
                     angle: float = DEFAULT_OVERHANG_ANGLE) -> bool:
    """Whether planes following the drift of `layers` (the sub-part's planar stack) would
    leave at least TILT_SAVING of its overhang less than `layers` do. True when the
    sub-part has no closed mesh to judge on (the planner then follows the bend, as before)."""
    spared = spared_overhang(subpart, layers, angle)
    return spared is None or spared >= TILT_SAVING * subpart.overhang_area


def spared_overhang(subpart: SubPart, layers: list[Layer],
                    angle: float = DEFAULT_OVERHANG_ANGLE) -> float | None:
    """Overhang area (mm²) of the sub-part's surface under planar `layers` that planes
    following their centroids' drift would bring within `angle`; None without a closed
    mesh."""
    from freecad_conformal.geometry.surface_mesh import surface_mesh

    mesh = surface_mesh(subpart.shape)
    if mesh is None or len(layers) < 2:
        return None
    corners = mesh.points[mesh.triangles]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    doubled = np.linalg.norm(cross, axis=1)
    normals = cross / np.maximum(doubled, 1e-300)[:, None]
    areas = 0.5 * doubled * mesh.scale
    build = layers[0].frame.n
    heights = corners.mean(axis=1) @ build
    limit = -overhang_threshold(angle)
    overhanging = normals @ build < limit
    local = _drift_normals(layers, build)[_layer_at(layers, build, heights)]
    turned_to = np.einsum("ij,ij->i", normals, local) >= limit
    return float(areas[overhanging & turned_to].sum())


def _drift_normals(layers: list[Layer], build: np.ndarray) -> np.ndarray:
    """Per layer, the unit drift of the section centroids over ±FOLLOW_REACH; the build
    direction where there is none or it leans past BEND_MAX_ANGLE (a jump, not a bend)."""
    centroids = layer_centroids(layers)
    reach = max(1, int(round(FOLLOW_REACH / max(layers[0].thickness, 1e-9))))
    index = np.arange(len(layers))
    drift = (centroids[np.minimum(index + reach, len(layers) - 1)]
             - centroids[np.maximum(index - reach, 0)])
    length = np.linalg.norm(drift, axis=1)
    unit = drift / np.maximum(length, 1e-300)[:, None]
    followable = (length > 0) & (unit @ build >= math.cos(BEND_MAX_ANGLE))
    return np.where(followable[:, None], unit, build)


def _layer_at(layers: list[Layer], build: np.ndarray, heights: np.ndarray) -> np.ndarray:
    """Per height along `build`, the index of the first layer whose top is not below it
    (the last layer above the stack)."""
    tops = np.array([float(np.asarray(layer.top_point, dtype=float) @ build) for layer in layers])
    return np.minimum(np.searchsorted(tops, heights), len(layers) - 1)
