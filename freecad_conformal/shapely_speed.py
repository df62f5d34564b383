"""Shapely's per-call wrappers taken off the hot path, and a direct mitred offset.

Shapely 2.1.0 (Debian 13's, under FreeCAD 1.0) wraps its creation and constructive
functions (`polygons`, `linearrings`, `buffer`, `simplify`, ...) in a check that inspects
the caller's arguments (`inspect.signature`) on every call, to warn about arguments given
by position: 5-10x the cost of making a small polygon (shapely issues #2280, #2282), and
the geometry methods (`buffer`, `intersection`, `difference`, `simplify`) pay it too: a
fifth of the jack's plan there, a tenth of the bottle's. Shapely 2.1.1 made the check
cheap. On 2.1.0 only, the public functions and geometry methods are given back their
unwrapped selves: the same functions, less the warning.

Shapely 2.0 and 2.1 also wrap every function in `multithreading_enabled`, which marks the
object arrays passed read-only for the call, against another thread changing them while
GEOS runs without the GIL. Shapely 2.2 dropped it (shapely #2338: about 1 µs a call, and
such sharing is the application's to avoid, as with numpy); this package shares no
geometry array between threads. Where it is still applied it is taken off the same way:
6 % of the wedge's plan on FreeCAD 1.0.
"""
from __future__ import annotations

import sys

#: The shapely release whose positional-argument check costs a signature inspection per call.
SLOW_RELEASE = "2.1.0"


def _wrapper_codes() -> list:
    """The code objects of the wrappers to take off in the installed shapely."""
    import shapely
    import shapely.decorators

    codes = []
    if shapely.__version__ == SLOW_RELEASE and hasattr(shapely.decorators, "deprecate_positional"):
        codes.append(shapely.decorators.deprecate_positional([])(lambda: None).__code__)
    guard = getattr(shapely.decorators, "multithreading_enabled", None)
    # Its inner function's code, read without calling it (shapely 2.2 warns when it is).
    codes += [const for const in getattr(getattr(guard, "__code__", None), "co_consts", ())
              if getattr(const, "co_name", None) == "wrapped"]
    return codes


def unwrap_slow_checks() -> int:
    """Replace the wrapped functions and geometry methods (`Polygon.buffer`,
    `intersection`, ...) of every shapely module loaded by the functions they wrap: shapely
    2.1.0's positional-argument check and 2.0/2.1's read-only marking (see the module
    docstring); the count of wrappers taken off (0 where there are none)."""
    codes = _wrapper_codes()
    if not codes:
        return 0
    modules = [module for name, module in list(sys.modules.items())
               if (name == "shapely" or name.startswith("shapely.")) and module is not None]
    owners = modules + [value for module in modules for value in list(vars(module).values())
                        if isinstance(value, type) and value.__module__.startswith("shapely")]
    replaced = 0
    for owner in {id(owner): owner for owner in owners}.values():
        for name, value in list(vars(owner).items()):
            unwrapped = value
            while (any(getattr(unwrapped, "__code__", None) is code for code in codes)
                   and hasattr(unwrapped, "__wrapped__")):
                unwrapped = unwrapped.__wrapped__
                replaced += 1
            if unwrapped is not value:
                setattr(owner, name, unwrapped)
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
