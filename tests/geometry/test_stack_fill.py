"""Layer fills made from both ends of a plan's stacks (`paths/stack_fill.py`): whatever share
a child makes, the skins, bridges and fills are those this process makes alone, bit for bit;
where the two sides meet, nothing is made twice over or left out; a child that sends
nothing leaves all the work here."""
from __future__ import annotations

import numpy as np
import pytest

from freecad_conformal.freecad_env import import_freecad
from freecad_conformal.layers.model import LayerSettings
from freecad_conformal.layers.plan import plan_layers
from freecad_conformal.paths import stack_fill
from freecad_conformal.paths.assemble import PathSettings, plan_paths
from freecad_conformal.decomposition.subparts import SubPart
from tests.geometry.own_fills import assert_each_layers_own_fill


def _stacks() -> list:
    """Two stacks whose layers all differ: a cone (tapered: each circle its own) and a
    tilted box on it (rests on its parent: no bottom skin)."""
    App, Part = import_freecad()
    cone = Part.makeCone(9.0, 4.0, 16.0)
    box = Part.makeBox(8.0, 5.0, 6.0, App.Vector(-4.0, -2.5, 16.0))
    box.rotate(App.Vector(0, 0, 19.0), App.Vector(1, 0, 0), 20.0)
    subs = [SubPart(0, cone, np.array([0.0, 0.0, 1.0]), volume=cone.Volume),
            SubPart(1, box, np.array([0.0, 0.0, 1.0]), parent=0, volume=box.Volume)]
    settings = LayerSettings()
    return [(plan_layers(sub, settings), sub.parent is not None) for sub in subs]


def _settings() -> PathSettings:
    settings = PathSettings()
    settings.feeds.bridge_infill = 30.0 * 60    # bridges filled apart: their regions count
    return settings


def _same(a: list, b: list) -> bool:
    """Two stacks' fills are the same: skins, bridges, islands, rings and chains exact."""
    for x, y in zip(a, b):
        if not (all(s.equals_exact(t, 0.0) for s, t in zip(x.skins, y.skins))
                and all((s is None and t is None) or s.equals_exact(t, 0.0)
                        for s, t in zip(x.bridges, y.bridges))):
            return False
        for f, g in zip(x.fills, y.fills):
            if len(f) != len(g):
                return False
            for i, j in zip(f, g):
                if not i.island.equals_exact(j.island, 0.0):
                    return False
                if [len(d) for d in i.depths] != [len(d) for d in j.depths] or not all(
                        np.array_equal(r, s) for d, e in zip(i.depths, j.depths)
                        for r, s in zip(d, e)):
                    return False
                if [(p.role, p.width) for p in i.infill] != [(p.role, p.width) for p in j.infill]:
                    return False
                if not all(np.array_equal(p.points, q.points) for p, q in zip(i.infill, j.infill)):
                    return False
    return len(a) == len(b)


#: The fill itself, before a test counts its calls.
MADE_ALONE = stack_fill.layer_fill


class _Replay:
    """A child that sends what `_from_the_end` makes for the request, `per_call` items at
    each `received()` (all at once when None; never, with per_call 0)."""

    per_call: int | None = None

    def __init__(self, module: str) -> None:
        self.items: list = []
        self.stopped = False

    def ask(self, request) -> None:
        counted, stack_fill.layer_fill = stack_fill.layer_fill, MADE_ALONE
        try:                           # the child's layers are not made here
            stack_fill._from_the_end(request, self.items.append)
        finally:
            stack_fill.layer_fill = counted

    def received(self) -> list:
        count = len(self.items) if self.per_call is None else self.per_call
        sent, self.items = self.items[:count], self.items[count:]
        return sent

    def stop(self) -> None:
        self.stopped = True


@pytest.fixture(scope="module")
def stacks():
    return _stacks()


@pytest.fixture(scope="module")
def alone(stacks):
    return stack_fill.stack_fills(stacks, _settings(), child=False)


def _made_here(monkeypatch) -> list:
    made: list = []
    original = stack_fill.layer_fill

    def counted(*args, **kwargs):
        made.append(args[2])
        return original(*args, **kwargs)

    monkeypatch.setattr(stack_fill, "layer_fill", counted)
    return made


@pytest.mark.parametrize("per_call", [None, 1, 3, 0])
def test_fills_shared_with_a_child_are_those_made_alone(stacks, alone, monkeypatch, per_call):
    monkeypatch.setattr(stack_fill, "MIN_CHILD_LAYERS", 0)
    monkeypatch.setattr(stack_fill, "can_start_child", lambda: True)
    monkeypatch.setattr(_Replay, "per_call", per_call)
    monkeypatch.setattr(stack_fill, "ChildPython", _Replay)
    made = _made_here(monkeypatch)
    shared = stack_fill.stack_fills(stacks, _settings())
    assert _same(shared, alone)
    total = sum(len(layers) for layers, _ in stacks)
    if per_call is None:
        assert made == []                      # the child had it all before the first layer
    elif per_call == 0:
        assert len(made) == total              # a mute child: all here
    else:
        # One side each from its end: here gets the first layers, the child the rest.
        assert 0 < len(made) < total


def test_a_real_child_makes_the_same_fills(stacks, alone, monkeypatch):
    monkeypatch.setattr(stack_fill, "MIN_CHILD_LAYERS", 0)
    shared = stack_fill.stack_fills(stacks, _settings())
    assert _same(shared, alone)


def test_too_few_layers_take_no_child(stacks, monkeypatch):
    started = []
    monkeypatch.setattr(stack_fill, "ChildPython", lambda module: started.append(module))
    monkeypatch.setattr(stack_fill, "can_start_child", lambda: True)
    monkeypatch.setattr(stack_fill, "MIN_CHILD_LAYERS", sum(len(s[0]) for s in stacks) + 1)
    stack_fill.stack_fills(stacks, _settings())
    assert started == []


def test_a_prism_of_many_layers_but_few_regions_takes_no_child(stacks, monkeypatch):
    """Its repeated layers are filled once here (the jack: 850 layers, 7 regions, 0.19 s
    of fills): a child would only start."""
    import dataclasses

    started = []
    monkeypatch.setattr(stack_fill, "ChildPython", lambda module: started.append(module))
    monkeypatch.setattr(stack_fill, "can_start_child", lambda: True)
    first = stacks[0][0][0]
    prism = [dataclasses.replace(first, index=i) for i in range(3 * stack_fill.MIN_CHILD_LAYERS)]
    made = stack_fill.stack_fills([(prism, False)], _settings())
    assert started == [] and len(made[0].fills) == len(prism)


def test_paths_from_shared_fills_are_each_layers_own_fill_in_order(stacks, monkeypatch):
    """Ordered from where the last layer ended, the shared fills give the paths each layer's
    own `fill_layer` gives from there (seams nearest the nozzle: the order matters)."""
    monkeypatch.setattr(stack_fill, "MIN_CHILD_LAYERS", 0)
    monkeypatch.setattr(stack_fill, "can_start_child", lambda: True)
    monkeypatch.setattr(stack_fill, "ChildPython", _Replay)
    settings = _settings()
    settings.fill.seam = "nearest"
    layers, _ = stacks[0]
    position = np.array([30.0, 0.0, 0.0])
    got = plan_paths(layers, settings, False, position)
    skins = stack_fill.stack_fills(stacks[:1], settings, child=False)[0]
    assert_each_layers_own_fill(layers, skins.skins, skins.bridges, got, settings, position)


def test_skins_read_for_the_paths_serve_the_cost_and_back(stacks, monkeypatch):
    """The paths keep the skins and bridges they read for the cost estimate (and use those
    it read): one reading of a stack either way."""
    from freecad_conformal.paths import assemble

    read: list[int] = []
    original = stack_fill.skin_at

    def counted(layers, i, *args):
        read.append(i)
        return original(layers, i, *args)

    monkeypatch.setattr(stack_fill, "skin_at", counted)
    settings = _settings()
    layers, rests = stacks[1]
    filled = assemble.stacks_filled([(layers, rests)], settings)[0]
    assert len(read) == len(layers)
    skins, bridges = assemble.solid_areas(layers, settings, rests)
    assert skins == filled.skins and bridges == filled.bridges and len(read) == len(layers)
    again = assemble.stacks_filled([(layers, rests)], settings)[0]
    assert again.skins == skins and len(read) == len(layers)


@pytest.fixture
def prestarting(monkeypatch):
    """`prestart` with the replaying child: the children it started."""
    started: list[_Replay] = []

    def start(module: str) -> _Replay:
        started.append(_Replay(module))
        return started[-1]

    monkeypatch.setattr(stack_fill, "ChildPython", start)
    monkeypatch.setattr(stack_fill, "can_start_child", lambda: True)
    monkeypatch.setattr(stack_fill, "can_stream", lambda: True)
    yield started
    stack_fill.drop_prestarted()


def test_a_child_started_while_the_plan_is_chosen_shares_fewer_layers(stacks, alone, monkeypatch,
                                                                      prestarting):
    """Started ahead, its start costs the fills nothing: it takes a share of stacks too
    small to repay starting one then."""
    monkeypatch.setattr(stack_fill, "MIN_CHILD_LAYERS", sum(len(s[0]) for s in stacks) + 1)
    monkeypatch.setattr(stack_fill, "MIN_PRESTARTED_LAYERS", 1)
    stack_fill.prestart()
    stack_fill.prestart()                       # one child, however often asked
    made = _made_here(monkeypatch)
    shared = stack_fill.stack_fills(stacks, _settings())
    assert _same(shared, alone)
    assert made == [] and len(prestarting) == 1     # the child had it all
    # Taken: the next fills start no other and find none ahead.
    again = stack_fill.stack_fills(stacks, _settings())
    assert _same(again, alone) and len(prestarting) == 1


def test_a_child_started_ahead_is_ended_where_it_does_not_pay(stacks, alone, monkeypatch,
                                                              prestarting):
    monkeypatch.setattr(stack_fill, "MIN_PRESTARTED_LAYERS", sum(len(s[0]) for s in stacks) + 1)
    monkeypatch.setattr(stack_fill, "MIN_CHILD_LAYERS", 10 ** 6)
    stack_fill.prestart()
    made = _made_here(monkeypatch)
    assert _same(stack_fill.stack_fills(stacks, _settings()), alone)
    assert len(made) == sum(len(s[0]) for s in stacks)
    assert len(prestarting) == 1 and prestarting[0].stopped


def test_a_failed_job_ends_the_child_started_for_its_paths(monkeypatch, prestarting):
    from freecad_conformal.errors import PlanError
    from freecad_conformal.geometry.samples import load_part
    from freecad_conformal.jobs import plan as job

    def refused(*args, **kwargs):
        raise PlanError("no plan")

    monkeypatch.setattr(job, "choose_plan", refused)
    with pytest.raises(PlanError):
        job.plan_additive(load_part("bracket")[0], job.PlanOptions())
    assert len(prestarting) == 1 and prestarting[0].stopped
    assert not stack_fill._PRESTARTED


def _prism_a_hair_apart() -> list:
    """A prism's layers whose regions agree to `SAME_FILL` but not to the last bit: a box of
    24 layers, its upper half moved 2e-15 mm (a turned part's sections carry such
    rounding). The layers of one parity share one key, and so one fill."""
    import dataclasses

    import shapely

    App, Part = import_freecad()
    box = Part.makeBox(12.0, 7.0, 4.8, App.Vector(0.3, 0.7, 0.0))
    layers = plan_layers(SubPart(0, box, np.array([0.0, 0.0, 1.0]), volume=box.Volume),
                         LayerSettings())
    moved = [dataclasses.replace(layer, region=shapely.transform(layer.region, lambda xy: xy + 2e-15))
             if k >= len(layers) // 2 else layer for k, layer in enumerate(layers)]
    return [(moved, False)]


@pytest.mark.parametrize("per_call", [1, 3, 7])
def test_layers_of_one_key_share_the_first_ones_fill_whoever_makes_it(monkeypatch, per_call):
    """Each side shared the fill it made first: here the lowest layer's of a key, in the
    child the highest's. Where the two met (timing) decided which layers took which, and
    a spool's G-code varied from run to run. Now every layer takes the fill of the first
    layer of its key, as when this process makes them all."""
    stacks = _prism_a_hair_apart()
    layers = stacks[0][0]
    assert len({layer.region.wkb for layer in layers}) == 2
    alone = stack_fill.stack_fills(stacks, _settings(), child=False)
    monkeypatch.setattr(stack_fill, "MIN_CHILD_LAYERS", 0)
    monkeypatch.setattr(stack_fill, "can_start_child", lambda: True)
    monkeypatch.setattr(stack_fill, "_distinct", lambda stacks: 10 ** 6)
    monkeypatch.setattr(_Replay, "per_call", per_call)
    monkeypatch.setattr(stack_fill, "ChildPython", _Replay)
    made = _made_here(monkeypatch)
    shared = stack_fill.stack_fills(stacks, _settings())
    assert 0 < len(made) < len(layers)         # both sides made some
    assert _same(shared, alone)
