"""Every layer's skin, bridge and fill of a plan's stacks, made from both ends at once.

A layer's skin and bridge (`paths.map3d`) and its islands filled (`fill2d.layer_fill`) do not
depend on where the nozzle is: only their order does (`fill2d.ordered_fill`, done later
along the plan). With enough layers a child Python (`child_python.py`) makes them from the
last layer back while this process goes from the first; where the two meet this process
stops and the child is ended. The child's layers come back pickled (exact doubles): the
same fills, bit for bit, as this process makes. Layers the same to `SAME_FILL` (a prism's,
but for rounding) share one fill: the one made from the first of them (`_canonical`),
whichever side made it. Each side shares the first it made, and where the two meet
depends on timing: a shared fill came from another layer from run to run (1e-15 mm
apart), and on a spool's symmetric pieces a tie in the paths' order broke either way.
Without a child (FreeCAD's GUI,
one core, a pool's worker, a child that died) this process makes them all. A plan's job
starts the child while it chooses the plan (`prestart`), so that it is ready for the paths.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Sequence

import shapely

from freecad_conformal.child_python import ChildPython, can_start_child, can_stream, serve_items
from freecad_conformal.geometry.loops import grid_key
from freecad_conformal.paths.fill2d import IslandFill, layer_fill
from freecad_conformal.paths.map3d import air_at, bridge_at, region_in, skin_at
from freecad_conformal.tolerances import COINCIDENT_POINTS

if TYPE_CHECKING:
    from freecad_conformal.layers.model import Layer

#: `paths.assemble.PathSettings`, which imports this module (fill, feeds, skins).
PathSettings = Any

#: Region polygons are simplified to this fraction of the bead width before path planning:
#: sections come at a 1 µm chord tolerance, far finer than a bead can follow, and the
#: points only cost time downstream.
SIMPLIFY_FRACTION = 1.0 / 40.0

#: Distinct fills (`_distinct`) from which a child pays: it starts in ~0.3 s (interpreter,
#: numpy, shapely) and a layer's fill takes 3-13 ms, once per distinct fill. Measured (alone
#: -> shared): Pump_Nut's 75 layers 0.98-1.11 -> 0.64-0.70 s, the screw's 211 (110 distinct)
#: 0.92-1.08 -> 0.61-0.64 s, the hinge's 200 0.62-0.70 -> 0.44-0.46 s; wedge_ok's 38 0.10 ->
#: 0.13-0.26 s, the jack's 850 layers of 7 regions 0.19 -> 0.21-0.24 s.
MIN_CHILD_LAYERS = 60
#: The same for a child started while the plan was chosen (`prestart`), ready when asked:
#: its share then pays from a few distinct fills. Measured (alone -> shared, fills only):
#: Pump_Nut's 17 distinct 0.79-0.81 -> 0.37-0.41 s, the screw's 43 0.29-0.58 -> 0.21-0.24 s,
#: revolved_sphere's 50 0.28 -> 0.14-0.16 s, wedge_ok's 38 0.13 -> 0.08 s; below ten the
#: request's trip eats the share (the jack's 16: 0.14-0.15 s either way).
MIN_PRESTARTED_LAYERS = 10

#: The child's module (`python -m`).
CHILD_MODULE = "freecad_conformal.paths.stack_fill"


@dataclass
class StackFill:
    """One stack's skins, bridges (None per layer where bridges are not filled apart) and
    per layer its islands filled, in layer order."""

    skins: list
    bridges: list
    fills: list[list[IslandFill]]


def internal_bridge_area(settings) -> float:
    """The least sparse piece below a skin that makes the skin over it a bridge
    (`map3d.bridge_at`): `solid_below_area` where bridges print at a speed of their own,
    else none is (the same speed gains nothing from a second zigzag); a bridge over
    nothing is laid apart either way, from anchor to anchor."""
    return settings.fill.solid_below_area if settings.feeds.bridges_apart else math.inf


class _Maker:
    """Makes the layers of the stacks one at a time, in either direction: a layer's skin is
    kept for the layer above's bridge, and a fill already made for the same region, skin,
    bridge, thickness and layer parity (`fill_key`) is reused (a prism's layers repeat)."""

    def __init__(self, stacks: Sequence[tuple[Sequence[Layer], bool]], settings: PathSettings,
                 known: Sequence[tuple[list, list] | None]) -> None:
        self.stacks, self.settings = stacks, settings
        self.skins = [dict(enumerate(k[0])) if k else {} for k in known]
        self.bridges = [dict(enumerate(k[1])) if k else {} for k in known]
        self.fills: list[dict[int, list[IslandFill]]] = [{} for _ in stacks]
        self.made: dict[tuple, list[IslandFill]] = {}
        self.simplified: dict[bytes, object] = {}

    def skin(self, stack: int, i: int):
        found = self.skins[stack].get(i)
        if found is None:
            layers, rests = self.stacks[stack]
            found = skin_at(layers, i, self.settings.top_layers, self.settings.bottom_layers,
                            rests)
            self.skins[stack][i] = found
        return found

    def make(self, stack: int, i: int) -> tuple[object, object, list[IslandFill], tuple]:
        """(skin, bridge, fill, key) of layer i of the stack."""
        layers, _ = self.stacks[stack]
        settings, layer = self.settings, layers[i]
        skin = self.skin(stack, i)
        bridge = self.bridges[stack].get(i)
        if bridge is None:
            bridge = bridge_at(layers, i, skin, self.skin(stack, i - 1) if i else None,
                               internal_bridge_area(settings), settings.fill.bead_width)
        air = air_at(layers, i, bridge, settings.fill.bead_width)
        region = self.simplified_region(layer.region)
        anchors = None if air is None else region_in(layer, layers[i - 1])
        key = fill_key(region, skin, bridge, layer, air, anchors)
        fill = self.made.get(key)
        if fill is None:
            fill = layer_fill(region, settings.fill, layer.index, skin, layer.thickness, bridge,
                              air, anchors)
            self.made[key] = fill
        self.put(stack, i, skin, bridge, fill)
        return skin, bridge, fill, key

    def simplified_region(self, region):
        """The region simplified to `SIMPLIFY_FRACTION` of the bead, once per region the
        same bit for bit: a prism's layers repeat theirs (the table's 300 layers hold 7, and
        simplifying each took 0.13 s, a tenth of its paths)."""
        key = shapely.to_wkb(region)
        found = self.simplified.get(key)
        if found is None:
            found = region.simplify(self.settings.fill.bead_width * SIMPLIFY_FRACTION)
            self.simplified[key] = found
        return found

    def put(self, stack: int, i: int, skin, bridge, fill: list[IslandFill]) -> None:
        self.skins[stack][i] = skin
        self.bridges[stack][i] = bridge
        self.fills[stack][i] = fill

    def result(self) -> list[StackFill]:
        return [StackFill([self.skins[s][i] for i in range(len(layers))],
                          [self.bridges[s].get(i) for i in range(len(layers))],
                          [self.fills[s][i] for i in range(len(layers))])
                for s, (layers, _) in enumerate(self.stacks)]


#: Layer thicknesses and region coordinates this close (mm) are one in a fill's key. A
#: layer's thickness is a difference of levels and carries their rounding, and a turned
#: part's sections carry their turn's: a square tube's 0.2 mm layers came as
#: 0.19999999999999996 and 0.20000000000000018 mm thick, and built upside down its corners
#: at 0 and 1.5e-17 mm, so its 150 layers of one region were filled and costed as if they
#: differed. Points equal to rounding are one everywhere (`COINCIDENT_POINTS`).
SAME_FILL = COINCIDENT_POINTS


def fill_key(region, skin, bridge, layer: Layer, air=None, anchors=None) -> tuple:
    """What a layer's fill depends on, as a dictionary key: its (simplified) region, skin,
    bridge, the bridge's part over nothing and what anchors it, and its thickness, each to
    `SAME_FILL`, and its parity (the infill's angle)."""
    return (_grid_key(region), _grid_key(skin), _grid_key(bridge), _grid_key(air),
            _grid_key(anchors), round(layer.thickness / SAME_FILL), layer.index % 2)


def _grid_key(geometry) -> bytes | None:
    return None if geometry is None else grid_key(geometry, SAME_FILL)


def stack_fills(stacks: Sequence[tuple[Sequence[Layer], bool]], settings: PathSettings,
                known: Sequence[tuple[list, list] | None] | None = None,
                child: bool = True) -> list[StackFill]:
    """Skins, bridges and fills of every stack ((layers, rests on its parent)); `known`:
    per stack its (skins, bridges) where already read (`assemble.solid_areas`), else None.
    `child`: whether a child may take a share (see the module docstring)."""
    known = list(known) if known is not None else [None] * len(stacks)
    maker = _Maker(stacks, settings, known)
    units = [(s, i) for s, (layers, _) in enumerate(stacks) for i in range(len(layers))]
    helper = _helper(stacks, units) if child else None
    if helper is not None:
        helper.ask({"stacks": stacks, "settings": settings, "known": known})
    done_from = len(units)      # the child has made every unit from here on
    child_fills: dict[int, tuple[list[IslandFill], tuple]] = {}    # number: (fill, key)
    keys: list[tuple | None] = [None] * len(units)
    try:
        for k, (s, i) in enumerate(units):
            if helper is not None:
                for index, skin, bridge, number, made in helper.received():
                    if made is not None:
                        child_fills[number] = made
                    fill, keys[index] = child_fills[number]
                    maker.put(*units[index], skin, bridge, fill)
                    done_from = index
            if k >= done_from:
                break
            keys[k] = maker.make(s, i)[3]
    finally:
        if helper is not None:
            helper.stop()
    if done_from < len(units):
        _canonical(maker, units, keys, done_from)
    return maker.result()


def _canonical(maker: _Maker, units: list, keys: list, done_from: int) -> None:
    """Every layer given the fill of the first layer of its key: this process made the
    first ones of its share in order, so only a key whose first layer lies in the child's
    share (which shares the fill of the last it met) has its fill made again here, from
    that layer."""
    first: dict[tuple, int] = {}
    count: dict[tuple, int] = {}
    for index, key in enumerate(keys):
        first.setdefault(key, index)
        count[key] = count.get(key, 0) + 1
    fills: dict[tuple, list[IslandFill]] = {}
    for key, index in first.items():
        if index >= done_from and count[key] > 1:
            maker.made.pop(key, None)
            maker.make(*units[index])
        s, i = units[index]
        fills[key] = maker.fills[s][i]
    for index, key in enumerate(keys[done_from:], start=done_from):
        s, i = units[index]
        maker.fills[s][i] = fills[key]


#: A child started ahead (`prestart`), not yet asked.
_PRESTARTED: list[ChildPython] = []


def prestart() -> None:
    """Start the child the next `stack_fills` shares its fills with now, while the plan is
    chosen (a plan's job calls it first): its start (interpreter, numpy, shapely and the
    fill modules, 0.45 s measured on the bottle's) then costs the fills nothing, and fewer
    layers repay it. Nothing where no child may start; `drop_prestarted` ends one unused."""
    if not _PRESTARTED and can_stream() and can_start_child():
        _PRESTARTED.append(ChildPython(CHILD_MODULE))


def drop_prestarted() -> None:
    """End the child `prestart` started, if no `stack_fills` took it (the job failed, or
    made no paths)."""
    while _PRESTARTED:
        _PRESTARTED.pop().stop()


def _helper(stacks: Sequence[tuple[Sequence[Layer], bool]], units: list) -> ChildPython | None:
    """The child to share the stacks' fills with: the one started ahead, or one started now
    where enough distinct fills repay its start; None where none pays or may start."""
    ready = _PRESTARTED.pop() if _PRESTARTED else None
    least = MIN_PRESTARTED_LAYERS if ready is not None else MIN_CHILD_LAYERS
    if len(units) >= least and _distinct(stacks) >= least:
        if ready is not None:
            return ready
        if can_stream() and can_start_child():
            return ChildPython(CHILD_MODULE)
    if ready is not None:
        ready.stop()
    return None


def _distinct(stacks: Sequence[tuple[Sequence[Layer], bool]]) -> int:
    """How many distinct fills the stacks' layers take, about: their regions, each at the
    layer parities it meets (a prism's repeat: filled once a parity). Regions alone, read
    to rounding, counted a pipe tee's 409 layers as 42, and its 103 fills, 2 s of them,
    were made without a child."""
    return len({(_grid_key(layer.region), layer.index % 2)
                for layers, _ in stacks for layer in layers})


def _from_the_end(request: dict, send: Callable[[object], None]) -> None:
    """Child side: make the units from the last back, sending each as (unit, skin, bridge,
    fill number, (fill, fill key) or None when that number was sent before)."""
    stacks, settings = request["stacks"], request["settings"]
    maker = _Maker(stacks, settings, request["known"])
    units = [(s, i) for s, (layers, _) in enumerate(stacks) for i in range(len(layers))]
    numbers: dict[tuple, int] = {}
    for index in reversed(range(len(units))):
        skin, bridge, fill, key = maker.make(*units[index])
        number = numbers.get(key)
        if number is None:
            number = numbers[key] = len(numbers)
            send((index, skin, bridge, number, (fill, key)))
        else:
            send((index, skin, bridge, number, None))


def _preload() -> None:
    """While the parent still chooses its plan (`prestart`): the layers' module, which the
    request's unpickling needs (this module brought the fills'), at the lowest priority:
    the choice's own work (OCC's Booleans and meshes run on every core) goes first."""
    if hasattr(os, "nice"):
        os.nice(19)
    import freecad_conformal.layers.model  # noqa: F401


if __name__ == "__main__":
    serve_items(_from_the_end, _preload)
