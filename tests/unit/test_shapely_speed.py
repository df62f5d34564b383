"""Shapely 2.1.0's per-call signature inspection is taken off our hot path
(freecad_conformal/shapely_speed.py), and nothing else is touched."""
from __future__ import annotations

import functools
import inspect
import sys
import types
import warnings

import pytest

from freecad_conformal import shapely_speed


def _fake_shapely(version: str) -> tuple[types.ModuleType, dict]:
    """A package shaped as shapely 2.1.0 is: a checking decorator (its per-call
    `inspect.signature` included), a submodule of checked and plain functions, and the
    top-level names re-exported from it."""
    package = types.ModuleType("shapely")
    package.__version__ = version
    decorators = types.ModuleType("shapely.decorators")

    def deprecate_positional(should_be_kwargs, category=DeprecationWarning):
        def decorator(func):
            @functools.wraps(func)
            def wrapper(*args, **kwargs):
                value = func(*args, **kwargs)
                bound = inspect.signature(func).bind_partial(*args)
                if any(name in should_be_kwargs for name in bound.arguments):
                    warnings.warn(f"positional argument for {func.__name__}", category, stacklevel=2)
                return value
            return wrapper
        return decorator

    decorators.deprecate_positional = deprecate_positional
    creation = types.ModuleType("shapely.creation")

    def polygons(shell, holes=None, indices=None):
        return ("polygon", shell, holes, indices)

    def plain(x):
        return x

    creation.polygons = deprecate_positional(["indices"])(polygons)
    creation.plain = plain
    geometry = types.ModuleType("shapely.geometry.base")

    def buffer(self, distance, quad_segs=16):
        return ("buffered", distance, quad_segs)

    # A geometry class, as shapely's, whose method is checked the same way.
    geometry.BaseGeometry = type("BaseGeometry", (), {
        "__module__": "shapely.geometry.base",
        "buffer": deprecate_positional(["quad_segs"])(buffer)})
    package.decorators, package.creation = decorators, creation
    package.polygons, package.plain = creation.polygons, creation.plain
    originals = {"polygons": polygons, "plain": plain, "buffer": buffer}
    return package, {"shapely": package, "shapely.decorators": decorators,
                     "shapely.creation": creation, "shapely.geometry.base": geometry}, originals


def test_the_slow_release_gets_its_functions_unwrapped(monkeypatch):
    package, modules, originals = _fake_shapely(shapely_speed.SLOW_RELEASE)
    for name, module in modules.items():
        monkeypatch.setitem(sys.modules, name, module)
    with pytest.warns(DeprecationWarning):
        package.polygons("shell", None, "given by position")
    # The top-level name and the submodule's (both are what callers look up) and the
    # geometry method.
    assert shapely_speed.unwrap_slow_checks() == 3
    assert package.polygons is originals["polygons"]
    assert package.creation.polygons is originals["polygons"]
    base = modules["shapely.geometry.base"].BaseGeometry
    assert base.__dict__["buffer"] is originals["buffer"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert base().buffer(1.0, 8) == ("buffered", 1.0, 8)
    assert package.plain is originals["plain"] and package.creation.plain is originals["plain"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert package.polygons("shell", None, 3) == ("polygon", "shell", None, 3)
    assert shapely_speed.unwrap_slow_checks() == 0     # nothing left to unwrap


def _guarded(package: types.ModuleType, modules: dict) -> dict:
    """`package` given shapely 2.0/2.1's read-only marking of object arrays around each
    call, applied under its checks as shapely applies it; the guarded functions."""
    import numpy as np

    decorators = modules["shapely.decorators"]

    def multithreading_enabled(func):
        @functools.wraps(func)
        def wrapped(*args, **kwargs):
            arrays = [a for a in args if isinstance(a, np.ndarray) and a.dtype == object]
            flags = [a.flags.writeable for a in arrays]
            try:
                for a in arrays:
                    a.flags.writeable = False
                return func(*args, **kwargs)
            finally:
                for a, flag in zip(arrays, flags):
                    a.flags.writeable = flag
        return wrapped

    decorators.multithreading_enabled = multithreading_enabled
    creation = modules["shapely.creation"]

    def area(geometry):
        return ("area", geometry)

    guarded = multithreading_enabled(area)
    creation.area = package.area = guarded
    # shapely's order: the check outside, the marking inside
    checked = decorators.deprecate_positional(["indices"])(multithreading_enabled(
        creation.polygons.__wrapped__))
    creation.polygons = package.polygons = checked
    return {"area": area}


@pytest.mark.parametrize("version", ["2.0.7", "2.1.0", "2.1.1"])
def test_the_read_only_marking_is_taken_off_where_shapely_applies_it(monkeypatch, version):
    package, modules, originals = _fake_shapely(version)
    originals.update(_guarded(package, modules))
    for name, module in modules.items():
        monkeypatch.setitem(sys.modules, name, module)
    shapely_speed.unwrap_slow_checks()
    assert package.area is originals["area"] and package.creation.area is originals["area"]
    if version == shapely_speed.SLOW_RELEASE:
        assert package.polygons is originals["polygons"]
    else:       # the cheap check stays; the marking under it goes only with it
        assert package.polygons.__wrapped__.__wrapped__ is originals["polygons"]
    assert package.plain is originals["plain"]
    assert shapely_speed.unwrap_slow_checks() == 0


def test_a_release_without_the_marking_loses_nothing(monkeypatch):
    """Shapely 2.2 keeps the decorator (deprecated: it warns when applied) but applies it
    to nothing: reading its code must not apply it, and nothing is replaced."""
    package, modules, _ = _fake_shapely("2.2.0")

    def multithreading_enabled(func):
        warnings.warn("multithreading_enabled is deprecated", FutureWarning, stacklevel=2)

        @functools.wraps(func)
        def wrapped(*args, **kwargs):
            return func(*args, **kwargs)
        return wrapped

    modules["shapely.decorators"].multithreading_enabled = multithreading_enabled
    for name, module in modules.items():
        monkeypatch.setitem(sys.modules, name, module)
    checked = package.polygons
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert shapely_speed.unwrap_slow_checks() == 0
    assert package.polygons is checked


@pytest.mark.parametrize("version", ["2.0.7", "2.1.1", "2.2.0"])
def test_other_releases_are_left_alone(monkeypatch, version):
    package, modules, _ = _fake_shapely(version)
    for name, module in modules.items():
        monkeypatch.setitem(sys.modules, name, module)
    checked = package.polygons
    assert shapely_speed.unwrap_slow_checks() == 0
    assert package.polygons is checked and package.creation.polygons is checked


def test_the_installed_shapely_carries_no_slow_check_once_imported():
    """Importing the package is enough (freecad_conformal/__init__.py): no public shapely
    function still inspects its arguments on every call."""
    import shapely
    import shapely.decorators
    import shapely.geometry.base

    import freecad_conformal  # noqa: F401

    if not hasattr(shapely.decorators, "deprecate_positional"):
        pytest.skip(f"shapely {shapely.__version__} has no positional-argument check")
    check = shapely.decorators.deprecate_positional([])(lambda: None).__code__
    slow = [name for name, value in [*vars(shapely).items(),
                                     *vars(shapely.geometry.base.BaseGeometry).items()]
            if getattr(value, "__code__", None) is check]
    if shapely.__version__ != shapely_speed.SLOW_RELEASE:
        assert shapely_speed.unwrap_slow_checks() == 0
    else:
        assert slow == []
        assert shapely.Polygon([(0, 0), (1, 0), (1, 1)]).area == pytest.approx(0.5)
    guards = shapely_speed._wrapper_codes()
    guarded = [name for name, value in [*vars(shapely).items(),
                                        *vars(shapely.geometry.base.BaseGeometry).items()]
               if any(getattr(value, "__code__", None) is code for code in guards)]
    assert guarded == []


def _shapes():
    """Islands as sections give them: convex and not, with a hole, two islands, a sliver
    with a spike, a rectangle an offset empties, and nothing."""
    import shapely
    from shapely.geometry import MultiPolygon, Polygon

    ring = Polygon([(0, 0), (30, 0), (30, 20), (0, 20)], [[(5, 5), (25, 5), (25, 15), (5, 15)]])
    return [Polygon([(0, 0), (10, 0), (10, 8), (3, 10), (0, 6)]),
            Polygon([(0, 0), (20, 0), (20, 20), (10, 2), (0, 20)]),
            ring,
            MultiPolygon([ring, Polygon([(40, 0), (45, 0), (45, 5), (40, 5)])]),
            Polygon([(0, 0), (10, 0), (10, 1), (5, 1.0000001), (5, 6), (4.9999, 1), (0, 1)]),
            Polygon([(0, 0), (1, 0), (1, 0.5), (0, 0.5)]),
            shapely.Polygon()]


@pytest.mark.parametrize("distance", [-0.6, -0.2, 0.2, 1.5])
@pytest.mark.parametrize("limit", [1.0, 2.0, 5.0])
def test_the_mitred_offset_is_the_public_calls_geometry(distance, limit):
    """Byte for byte: the fills' loops (and so the G-code) must not move."""
    import numpy as np

    for shape in _shapes():
        with np.errstate(divide="ignore", invalid="ignore"):
            expected = shape.buffer(distance, join_style="mitre", mitre_limit=limit)
            found = shapely_speed.mitred_buffer(shape, distance, limit)
        assert found.wkb == expected.wkb, (shape.wkt, distance, limit)
        assert type(found) is type(expected)


def test_a_shapely_whose_ufunc_answers_otherwise_gets_the_public_call(monkeypatch):
    """Its internals are not shapely's promise: a ufunc that takes other arguments, or
    gives another geometry for these, is not used."""
    import numpy as np
    import shapely

    real = shapely.lib.buffer

    def other_joins(geometry, distance, segments, cap, join, *rest):
        # join styles numbered otherwise: what shapely calls mitre, GEOS bevels
        return real(geometry, distance, segments, cap,
                    np.intc(shapely.BufferJoinStyle.bevel), *rest)

    def other_arguments(geometry, distance, segments, cap, join, limit):   # one fewer
        return real(geometry, distance, segments, cap, join, limit, False)

    assert shapely_speed._mitred_through_ufunc(other_joins) is None
    assert shapely_speed._mitred_through_ufunc(other_arguments) is None
    assert shapely_speed._mitred_through_ufunc() is not None
    probe = shapely.Polygon([(0, 0), (4, 0), (4, 4)])
    public = probe.buffer(-0.5, join_style="mitre", mitre_limit=2.0).wkb
    monkeypatch.setattr(shapely_speed, "_MITRED", None)
    assert shapely_speed.mitred_buffer(probe, -0.5, 2.0).wkb == public
