"""Shapely 2.1.0's deprecation checks, taken off the hot path.

Shapely 2.1.0 (Debian 13's, under FreeCAD 1.0) wraps its creation and constructive
functions (`polygons`, `linearrings`, `buffer`, `simplify`, ...) in a check that inspects
the caller's arguments (`inspect.signature`) on every call, to warn about arguments given
by position: 5-10x the cost of making a small polygon (shapely issues #2280, #2282), and
the geometry methods (`buffer`, `intersection`, `difference`, `simplify`) pay it too: a
fifth of the jack's plan there, a tenth of the bottle's. Shapely 2.1.1 made the check
cheap. On 2.1.0 only, the public functions and geometry methods are given back their
unwrapped selves: the same functions, less the warning.
"""
from __future__ import annotations

import sys

#: The shapely release whose positional-argument check costs a signature inspection per call.
SLOW_RELEASE = "2.1.0"


def unwrap_slow_checks() -> int:
    """Replace shapely 2.1.0's checked functions and geometry methods (`Polygon.buffer`,
    `intersection`, ...) by the functions they wrap, in every shapely module loaded; the
    count replaced (0 on any other release)."""
    import shapely
    import shapely.decorators

    if shapely.__version__ != SLOW_RELEASE or not hasattr(shapely.decorators, "deprecate_positional"):
        return 0
    check = shapely.decorators.deprecate_positional([])(lambda: None).__code__
    modules = [module for name, module in list(sys.modules.items())
               if (name == "shapely" or name.startswith("shapely.")) and module is not None]
    owners = modules + [value for module in modules for value in list(vars(module).values())
                        if isinstance(value, type) and value.__module__.startswith("shapely")]
    replaced = 0
    for owner in {id(owner): owner for owner in owners}.values():
        for name, value in list(vars(owner).items()):
            if getattr(value, "__code__", None) is check and hasattr(value, "__wrapped__"):
                setattr(owner, name, value.__wrapped__)
                replaced += 1
    return replaced


def _mitred_through_ufunc(ufunc=None):
    """GEOS's buffer ufunc (`ufunc`, default shapely's) called as `shapely.buffer` calls
    it, when it answers a probe as that does; None otherwise (a shapely whose internals
    differ: they are not its promise)."""
    import numpy as np
    import shapely

    try:
        ufunc = shapely.lib.buffer if ufunc is None else ufunc
        segments = np.intc(8)       # shapely.buffer's defaults: 8 segments a quarter circle,
        cap = np.intc(shapely.BufferCapStyle.round)     # round caps
        mitre = np.intc(shapely.BufferJoinStyle.mitre)

        def mitred(geometry, distance: float, limit: float):
            return ufunc(geometry, distance, segments, cap, mitre, limit, False)

        probe = shapely.Polygon([(0, 0), (10, 0), (10, 8), (3, 10), (0, 6)])
        for distance in (-0.7, 0.4):
            if (mitred(probe, distance, 2.0).wkb
                    != probe.buffer(distance, join_style="mitre", mitre_limit=2.0).wkb):
                return None
        return mitred
    except Exception:       # noqa: BLE001  (any difference in shapely's internals: the public call)
        return None


_MITRED = _mitred_through_ufunc()


def mitred_buffer(geometry, distance: float, mitre_limit: float):
    """`geometry.buffer(distance, join_style="mitre", mitre_limit=mitre_limit)`, the same
    geometry, without the public call's argument handling: 15 µs of its 27 against GEOS's
    12 on a small polygon, where the fills and the cost estimate offset every island's
    loops (the wedge's 800 offsets per plan candidate pass)."""
    if _MITRED is None:
        return geometry.buffer(distance, join_style="mitre", mitre_limit=mitre_limit)
    return _MITRED(geometry, distance, mitre_limit)
