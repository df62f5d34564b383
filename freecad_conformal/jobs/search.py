"""The plan a user pays least for: candidate plans ranked by residual overhang, then cost.

Candidates for a part of one solid with `root="auto"`:
- the whole solid in one piece along every direction that leaves it support-free standing
  on a flat face (the cube's 26 directions and the normals of its largest planar faces,
  `geometry/overhang.orientation_candidates`): a planar slicer's "place on face";
- when no such direction exists, its decomposition (`decomposition/decompose.py`, which
  plans from the root as placed and from the single direction with least overhang and keeps
  the one that leaves less), and, should that leave any overhang or fail (no collision-free
  order), the solid built whole along its best single direction (splitting that does not
  remove the overhang only adds walls and skins), unless that leaves more overhang than the
  decomposition: it cannot win, and a note says what it would leave.
Each is laid out on the machine as it would be built (`jobs/plan.machine_plan`), sliced, and
costed without planning paths (`paths/cost.py`: within 10 % of the full plan's estimate).
Whole orientations are first costed on every `COARSE_EVERY`-th layer (`sampled_layers`),
then only those within `COARSE_MARGIN` of the best by the objective are sliced exactly
(with 3-D layers where the axis bends; of the builds along d and −d only the better sampled
one) and costed again, none when an exactly costed
candidate leads them all by `EXACT_LEAD`; the others stay ranked by their coarse cost,
behind every exactly costed candidate, so a coarse estimate never wins.
The plan with the least residual overhang wins; among those within `OVERHANG_TIE` of it,
the cheapest by the objective: time, material, or balanced (each candidate's time and
material over the least of either, summed).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from freecad_conformal.decomposition.planner import MIN_SAVING
from freecad_conformal.decomposition.subparts import WHOLE_AFTER_FAILURE, BuildPlan
from freecad_conformal.errors import BeyondTravelError, GeometryError, PlanError
from freecad_conformal.geometry.overhang import (MIN_BASE_AREA, base_area, best_single_direction,
                                                 orientation_candidates, overhang_area)
from freecad_conformal.geometry.frames import vector_text
from freecad_conformal.geometry.sections import extent_along
from freecad_conformal.layers.model import Layer
from freecad_conformal.layers.plan import plan_layers, sampled_layers
from freecad_conformal.paths.assemble import PathSettings
from freecad_conformal.paths.cost import Motion, PlanCost, plan_cost
from freecad_conformal.settings.plan import OBJECTIVES

#: Residual overhang (mm²) this close to the least is a tie, settled by cost.
OVERHANG_TIE = 1.0
#: At most this many support-free whole orientations are costed (lowest first: fewest layers).
MAX_WHOLE_ORIENTATIONS = 8
#: Whole orientations are ranked on every this-many-th layer first: three, the default
#: count of solid top and bottom layers, so that one sampled skin layer stands for them.
COARSE_EVERY = 3
#: Of the sampled layers, every this-many-th of a run whose sections change evenly is filled
#: and costed, those between read off the line between their costs (`paths.cost`'s
#: `_read_off_places`): sliced_cylinder's three orientations cost in 0.69 s instead of 1.71 s,
#: each within 0.1 % of its time and material with every sampled layer filled, and every
#: whole orientation of the shared parts, the samples and the own parts within 1.3 %.
#: Five gave sliced_cylinder 0.52 s, but errors 3-4x as large (1.6 % on the wedge).
COARSE_BETWEEN = 3
#: Coarse candidates whose score is within this share of the best time or material (the
#: balanced score: within this much of the best sum) are costed exactly before the choice.
COARSE_MARGIN = 0.03
#: Coarse candidates all behind an exactly costed one of tied overhang by more than this
#: (the same units) are not sliced: none can win. The sampled estimate overstates the exact
#: time and material by 2.5 % and 2.3 % at most, 4.5 % both at once (the wedge; every whole
#: orientation of the shared parts, the samples and the own parts costed both ways, layers
#: read off as COARSE_BETWEEN says; 2.8 % and 2.4 % filling each), so even both at once
#: (the balanced score) stay within it. It understates more (8.4 % of the time on branch45,
#: whose exact layers are 3-D), which only widens the gap.
EXACT_LEAD = 0.06


def ordinal(n: int) -> str:
    """1st, 2nd, 3rd, 4th, … 11th, 12th, 13th, … 21st."""
    suffix = "th" if n % 100 in (11, 12, 13) else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


class CostWhenRead:
    """A plan's cost (`paths/cost.plan_cost`), computed when first read: a search left with
    one candidate compares nothing (the bottle's decomposition: 1.0 s of its 2.8 s choice),
    and the job reports that plan's own figures instead. Twins share one."""

    def __init__(self, plan: BuildPlan, layers: dict, path_settings: PathSettings,
                 motion: Motion) -> None:
        self._args = (plan, layers, path_settings, motion)
        self._cost: PlanCost | None = None

    @property
    def known(self) -> bool:
        """Whether the cost was computed (read) already."""
        return self._cost is not None

    def __getattr__(self, name: str):
        if name.startswith("_"):
            raise AttributeError(name)
        if self._cost is None:
            self._cost = plan_cost(*self._args)
        return getattr(self._cost, name)


@dataclass
class Candidate:
    """One way to build the part, laid out on the machine, sliced and costed."""

    label: str
    placed: object
    plan: BuildPlan
    layers: dict[int, list[Layer]]
    cost: PlanCost | CostWhenRead
    #: made by the decomposition (False: the solid built whole)
    split: bool = False
    #: costed on exact layers (False: on sampled ones, `layers` empty; see the docstring)
    exact: bool = True
    #: the build direction of the solid built whole, in the part's frame (None: decomposed)
    direction: tuple[float, float, float] | None = None
    #: the label of the exactly costed candidate built whole the opposite way, for a
    #: candidate left sampled as its mirror (`_mirror_costed`)
    mirror_of: str | None = None

    @property
    def overhang(self) -> float:
        return float(self.plan.support_area)

    @property
    def costed(self) -> bool:
        """Whether its cost is known (a `CostWhenRead` not read yet is not)."""
        return not isinstance(self.cost, CostWhenRead) or self.cost.known

    @property
    def sub_parts(self) -> int:
        """Sub-parts built: those holding a layer once sliced; all of the plan's before (a
        coarse candidate keeps no layers, and its rows read 0 sub-parts)."""
        if not self.exact:
            return len(self.plan.subparts)
        return sum(1 for sub in self.plan.subparts if self.layers.get(sub.index))

    def row(self, chosen: bool = False, figures: tuple[float, float] | None = None,
            same_build_as: str | None = None) -> dict:
        """The candidate as report data; `figures` (time s, material mm³) are the built
        plan's own, given for a candidate that was compared with none (estimate "plan");
        `same_build_as`, the label of a candidate ranked before it that builds the same;
        `mirror_of`, the label of the sliced candidate built the opposite way, for one left
        sampled as its mirror."""
        if figures is not None:
            (seconds, material), estimate = figures, "plan"
        else:
            seconds, material = self.cost.seconds, self.cost.material
            estimate = "layers" if self.exact else f"every {ordinal(COARSE_EVERY)} layer"
        return {"label": self.label, "sub_parts": self.sub_parts,
                "residual_overhang_mm2": self.overhang, "material_mm3": material,
                "time_s": seconds, "estimate": estimate, "chosen": chosen,
                "same_build_as": same_build_as, "mirror_of": self.mirror_of}


def builds(candidates: list[Candidate]) -> int:
    """How many different builds the candidates are: twins (`_as_twin`, the same build)
    share one cost, and Pump_Nut's and the sphere's two candidates are one build."""
    return len({id(c.cost) for c in candidates})


def compared(candidates: list[Candidate]) -> bool:
    """Whether the candidates hold two costs to compare (two builds)."""
    return builds(candidates) > 1


def twin_labels(candidates: list[Candidate]) -> list[str | None]:
    """For each candidate, the label of the first one before it that is the same build
    (shares its cost), None for the first of each build."""
    first: dict[int, str] = {}
    labels = []
    for c in candidates:
        labels.append(first.get(id(c.cost)))
        first.setdefault(id(c.cost), c.label)
    return labels


def ranked(candidates: list[Candidate], objective: str) -> list[Candidate]:
    """Best first: least residual overhang (within OVERHANG_TIE), then the objective."""
    if objective not in OBJECTIVES:
        raise PlanError(f"objective must be one of {', '.join(OBJECTIVES)}, got {objective!r}")
    if not compared(candidates):
        return list(candidates)   # their cost is not read (CostWhenRead)
    least = min(c.overhang for c in candidates)
    exact = [c for c in candidates if c.exact and c.overhang <= least + OVERHANG_TIE]
    if len(exact) == 1 and not exact[0].costed:
        # The one exactly costed plan of least overhang wins whatever it costs (a coarse
        # estimate never outranks it): its cost is not read, the others are ranked among
        # themselves (the sliced cylinder's refined orientation: 0.5 s of its choice).
        return exact + _by_score([c for c in candidates if c is not exact[0]], least, objective)
    return _by_score(candidates, least, objective)


def _by_score(candidates: list[Candidate], least: float, objective: str) -> list[Candidate]:
    """`candidates` sorted: overhang within OVERHANG_TIE of `least` first, exact costs before
    coarse ones, then by the objective among them."""
    if not candidates:
        return []
    value = _objective(candidates, objective)

    def score(c: Candidate) -> tuple[bool, bool, float, float]:
        return c.overhang > least + OVERHANG_TIE, not c.exact, value(c), c.overhang

    return sorted(candidates, key=score)


def _objective(candidates: list[Candidate], objective: str) -> Callable[[Candidate], float]:
    """The objective's value of a candidate among `candidates` (lower is better)."""
    fastest = min(c.cost.seconds for c in candidates) or 1.0
    leanest = min(c.cost.material for c in candidates) or 1.0
    return lambda c: {"time": c.cost.seconds, "material": c.cost.material,
                      "balanced": c.cost.seconds / fastest + c.cost.material / leanest}[objective]


def _whole_directions(solid, angle: float) -> list[np.ndarray]:
    """Directions that leave the whole solid support-free on a flat face, lowest first."""
    found = [d for d in orientation_candidates(solid)
             if overhang_area(solid, d, angle) <= MIN_SAVING and base_area(solid, d) >= MIN_BASE_AREA]

    def height(d: np.ndarray) -> float:
        low, high = extent_along(solid, d)
        return high - low

    return sorted(found, key=height)[:MAX_WHOLE_ORIENTATIONS]


def builds_whole(solid, angle: float) -> bool:
    """Whether some whole orientation leaves the solid support-free on a flat face (the
    directions `plan_candidates` costs first)."""
    return bool(_whole_directions(solid, angle))



def plan_candidates(solid, make_plan: Callable[[object, bool], tuple], layer_settings,
                    path_settings: PathSettings, motion: Motion, angle: float,
                    progress: Callable[[str], None] | None = None,
                    objective: str = "balanced",
                    child_request: Callable[[], dict] | None = None,
                    early_trial=None, split: bool = True) -> list[Candidate]:
    """Every candidate for one solid (see the module docstring). `make_plan(root, split)`
    returns (placed shape, plan) as `jobs/plan.machine_plan` lays it out with that root
    ("auto" or a direction of the part as given) and split (decompose, or build whole).
    `objective` picks which coarsely costed candidates are costed exactly.
    `child_request()` gives what a child Python needs to lay out and cost whole
    orientations as `make_plan` does (`jobs/coarse_child.py`); None: all are costed here.
    `early_trial`: the decomposition's trial child begun for the solid
    (`decomposition/trial.EarlyTrial`), stopped when whole orientations leave nothing to
    decompose (its core is then the coarse child's). `split=False` (a machine that cannot
    tilt the tool): no decomposition; without a support-free direction the solid is built
    whole along its best single direction, with support, as a planar slicer would."""
    directions = _whole_directions(solid, angle)
    if directions and early_trial is not None:
        early_trial.stop()
    makers: list[tuple[str, object, bool]] = [
        (f"whole along {vector_text(d)}", tuple(float(c) for c in d), False) for d in directions]
    if not makers and split:
        makers = [("decomposed", "auto", True)]
    elif not makers:
        best, _ = best_single_direction(solid, angle)
        makers = [(f"whole along {vector_text(best)}", tuple(float(c) for c in best), False)]
    child = None
    if child_request is not None and len(makers) > 1:
        from freecad_conformal.jobs.coarse_child import start_child

        weights = [_sampled_count(solid, d, layer_settings) for d in directions]
        child = start_child(child_request, [m[:2] for m in makers], weights, layer_settings,
                            path_settings, motion)
    try:
        found = _made(solid, makers, make_plan, layer_settings, path_settings, motion, angle,
                      progress, child)
    finally:
        if child is not None:
            child.stop()
    return _refined(found, layer_settings, path_settings, motion, objective)


def _sampled_count(solid, direction: np.ndarray, layer_settings) -> float:
    """About how many layers `coarse_candidate` slices of the solid built along
    `direction`: the work a child would take."""
    low, high = extent_along(solid, direction)
    return (high - low) / (layer_settings.thickness * COARSE_EVERY)


def _made(solid, makers: list, make_plan, layer_settings, path_settings: PathSettings,
          motion: Motion, angle: float, progress, child) -> list[Candidate]:
    """The candidates of `makers` (the whole builds `child` took costed there, the rest
    here), in their order, before any is costed exactly."""
    given = set(child.numbers) if child is not None else set()
    candidates: list[Candidate] = []
    failures: list[tuple[str, PlanError]] = []
    notes: list[str] = []
    numbers: list[int] = []       # the maker of each candidate, to keep their order
    waiting: list[tuple[int, Candidate]] = []     # (maker, laid out) the child costs

    def whole_along_best() -> None:
        # This loop reaches it.
        # Ties go to the earlier direction (+Z, the part as placed, first): the twin of a
        # decomposition that kept the part as placed and made no cut (a sphere's).
        direction, area = best_single_direction(solid, angle, tie=OVERHANG_TIE)
        label = f"whole along {vector_text(direction)}"
        best = min(candidates, key=lambda c: c.overhang, default=None)
        if best is not None and area > best.overhang + OVERHANG_TIE:
            # Residual overhang is ranked first: this build cannot win, and its cost
            # (without the support it would need) compares with nothing. Laying it out and
            # costing it took the bottle 2.1 s of its 5.1 s choice.
            best.plan.notes.append(f"{label}: the part built whole would leave {area:.1f} mm² "
                                   f"of overhang, more than {best.overhang:.1f}: not costed")
            return
        makers.append((label, tuple(float(c) for c in direction), False))

    for number, (label, root, split) in enumerate(makers):
        if progress is not None:
            progress(label)
        try:
            placed, plan = make_plan(root, split)
        except PlanError as exc:
            failures.append((label, exc))
            if split:
                # No support-free decomposition can be built (no collision-free order):
                # the part built whole, with its overhang, is what a user can still print.
                notes.append(f"no decomposition could be built ({exc}); built whole instead")
                whole_along_best()
            continue
        # The decomposition made no cut and built the solid whole along this very direction,
        # where this one stands: the same layers and cost (the connecting rod sliced its 320
        # layers twice, 7 s each).
        made = _as_twin(Candidate(label, placed, plan, {}, None, split, exact=False), candidates)
        if made is None and number in given:
            # The child costs it meanwhile.
            waiting.append((number, Candidate(label, placed, plan, {}, None, False,
                                              exact=False)))
            continue
        try:
            # The one candidate there will be (the part's only whole build, or the one a
            # failed decomposition left: the knob's) is costed on its layers at once: a
            # sampled estimate has nothing to rank, and then it was sliced again anyway
            # (0.44 s of the knob's 1.4 s choice).
            last = number == len(makers) - 1 and not candidates and not waiting
            if made is None and (split or last):
                made = _exact(label, placed, plan, split, layer_settings, path_settings, motion)
            elif made is None:
                made = coarse_candidate(label, placed, plan, layer_settings, path_settings, motion)
        except GeometryError as exc:
            # A sub-part OCC cannot slice (the bottle's decomposition on OCCT 7.8): this
            # candidate is lost, not the plan.
            failures.append((label, exc))
            if split:
                notes.append(f"the decomposition could not be sliced ({exc}); built whole "
                             "instead")
                whole_along_best()
            continue
        if made is None:
            failures.append((label, PlanError("the part is thinner than one layer")))
            continue
        plan.notes.extend(notes)
        if notes and not split:
            # Built whole because the decomposition failed: a cut may well save overhang.
            plan.support_reason = WHOLE_AFTER_FAILURE
        candidates.append(made)
        numbers.append(number)
        if split and plan.support_area > MIN_SAVING:
            # The decomposition did not remove all overhang (the table's splayed legs), or
            # kept more than turning the solid whole (a split OCC could not make): the solid
            # built whole along its best single direction is a candidate too, and wins when
            # it leaves no more overhang for less cost.
            whole_along_best()
    if waiting:
        for number, made in _collect(waiting, child, failures, layer_settings, path_settings,
                                     motion):
            candidates.append(made)
            numbers.append(number)
        candidates = [c for _, c in sorted(zip(numbers, candidates), key=lambda nc: nc[0])]
        numbers.sort()
    candidates = [c if makers[n][2] else dataclasses.replace(c, direction=makers[n][1])
                  for n, c in zip(numbers, candidates)]
    if not candidates:
        if len(failures) == 1:
            raise failures[0][1]
        if all(isinstance(exc, BeyondTravelError) for _, exc in failures):
            # Every way out of the travel: one message, not the same one for each.
            label, first = failures[0]
            raise BeyondTravelError(first.machine, f"{label}: {first.where}", len(failures))
        raise PlanError("no candidate plan could be made for the part: "
                        + "; ".join(f"{label}: {exc}" for label, exc in failures))
    return candidates


def _collect(waiting: list[tuple[int, Candidate]], child, failures: list, layer_settings,
             path_settings: PathSettings, motion: Motion) -> list[tuple[int, Candidate]]:
    """(maker, candidate) of the whole builds the child costed, with its estimates (costed
    here instead when the child gave no answer); what could not be costed fails as it would
    have here."""
    answers = child.results()
    by_number = dict(zip(child.numbers, answers or []))
    made: list[tuple[int, Candidate]] = []
    for number, laid in waiting:
        if answers is None:
            try:
                found = coarse_candidate(laid.label, laid.placed, laid.plan, layer_settings,
                                         path_settings, motion)
            except GeometryError as exc:
                failures.append((laid.label, exc))
                continue
        else:
            kind, value = by_number[number]
            if kind == "error":
                failures.append((laid.label, value))
                continue
            found = None if value is None else dataclasses.replace(laid, cost=value)
        if found is None:
            failures.append((laid.label, PlanError("the part is thinner than one layer")))
            continue
        made.append((number, found))
    return made


#: Sub-parts laid out within this (mm of box, relative volume, direction) are the same.
SAME_BUILD = 1e-6


def _same_build(a: BuildPlan, b: BuildPlan) -> bool:
    """Whether two plans build the same single sub-part along the same direction, where
    the layout put them: one volume, one build direction, one centre of mass and the same
    vertices (OCC's exact values; boxes are not: `BoundBox` and the optimal box are read
    from a triangulation when a shape has one)."""
    if len(a.subparts) != 1 or len(b.subparts) != 1:
        return False
    first, second = a.subparts[0], b.subparts[0]
    if not (np.allclose(first.build_direction, second.build_direction, atol=SAME_BUILD)
            and math.isclose(first.shape.Volume, second.shape.Volume, rel_tol=SAME_BUILD)
            and np.allclose(tuple(first.shape.CenterOfMass), tuple(second.shape.CenterOfMass),
                            atol=SAME_BUILD)):
        return False
    corners = [np.array(sorted(tuple(v.Point) for v in sub.shape.Vertexes)).reshape(-1, 3)
               for sub in (first, second)]
    return corners[0].shape == corners[1].shape and np.allclose(corners[0], corners[1],
                                                                 atol=SAME_BUILD)


def _as_twin(candidate: Candidate, candidates: list[Candidate]) -> Candidate | None:
    """`candidate` with the layers and cost of an exactly costed one among `candidates`
    that is the same build (`_same_build`); None when there is none."""
    twin = next((c for c in candidates if c.exact and _same_build(c.plan, candidate.plan)), None)
    if twin is None:
        return None
    return dataclasses.replace(candidate, layers=twin.layers, cost=twin.cost, exact=True)


#: Two whole builds whose directions' sum is this short (unit vectors) are mirrored.
MIRRORED = 1e-9


def _mirror_costed(candidate: Candidate, costed) -> Candidate | None:
    """The candidate among `costed`, exactly costed, that builds the solid whole along the
    opposite direction (None when there is none). Built along d and −d, a solid is cut by
    the same planes into mirrored sections: the two differ in which skins face up, where
    the layers start and the sparse infill's phase (up to 2.7 % on the T-block), all of
    which the sampled estimate reads too. On the 19 pairs both were costed exactly
    (samples, own parts, a gear, a comb, an I-beam, a perforated plate) the better sampled
    one was the better exact one, or within 0.002 % of it (the vase). Slicing and costing
    the other took 0.8 s of the gear's 1.4 s plan choice."""
    if candidate.direction is None:
        return None
    mirror = -np.asarray(candidate.direction)
    return next((other for other in costed
                 if other is not None and other.exact and other.direction is not None
                 and np.linalg.norm(mirror - np.asarray(other.direction)) < MIRRORED), None)


def _exact(label: str, placed, plan: BuildPlan, split: bool, layer_settings,
           path_settings: PathSettings, motion: Motion) -> Candidate | None:
    """The candidate sliced exactly and costed on them (when read); None if no sub-part
    holds a layer."""
    layers = {sub.index: plan_layers(sub, layer_settings) for sub in plan.ordered()}
    if not any(layers.values()):
        return None
    return Candidate(label, placed, plan, layers,
                     CostWhenRead(plan, layers, path_settings, motion), split)


def coarse_candidate(label: str, placed, plan: BuildPlan, layer_settings,
                     path_settings: PathSettings, motion: Motion) -> Candidate | None:
    """The candidate costed on sampled layers (`sampled_layers`), each standing for the
    layers around it; None if no sub-part holds a layer."""
    sampled = {sub.index: sampled_layers(sub, layer_settings, COARSE_EVERY)
               for sub in plan.ordered()}
    layers = {index: found for index, (found, _) in sampled.items()}
    if not any(layers.values()):
        return None
    skins = dataclasses.replace(
        path_settings, top_layers=-(-path_settings.top_layers // COARSE_EVERY),
        bottom_layers=-(-path_settings.bottom_layers // COARSE_EVERY))
    cost = plan_cost(plan, layers, skins, motion, COARSE_BETWEEN)
    # Each sampled layer stands for `weight` layers, in time (cooling slowdown included:
    # it is per layer) and material; the moves between sub-parts happen once.
    sampled_count = sum(len(found) for found in layers.values())
    weight = sum(w * len(layers[index]) for index, (_, w) in sampled.items()) / sampled_count
    seconds = cost.transition_seconds + weight * (cost.seconds - cost.transition_seconds)
    estimate = PlanCost(seconds, weight * cost.material, cost.subparts, cost.transition_seconds)
    return Candidate(label, placed, plan, {}, estimate, False, exact=False)


def _unit(objective: str, best: float) -> float:
    """What a margin on the objective's score is a share of: the best time or material, as
    the balanced score (a sum of such shares) counts them."""
    return 1.0 if objective == "balanced" else (best or 1.0)


def _behind_exact(contenders: list[Candidate], candidates: list[Candidate], least: float,
                  objective: str) -> bool:
    """Whether every coarse contender's score is more than EXACT_LEAD behind that of an
    exactly costed candidate whose overhang ties the least (scored together)."""
    rivals = [c for c in candidates if c.exact and c.overhang <= least + OVERHANG_TIE]
    if not rivals:
        return False
    value = _objective(contenders + rivals, objective)
    best = min(value(c) for c in rivals)
    return min(value(c) for c in contenders) > best + EXACT_LEAD * _unit(objective, best)


def _refined(candidates: list[Candidate], layer_settings, path_settings: PathSettings,
             motion: Motion, objective: str) -> list[Candidate]:
    """`candidates` with the coarse ones that might win costed exactly: the best coarse
    score and those within COARSE_MARGIN of it (ties of residual overhang only), but not
    the mirror of one costed so (`_mirror_costed`); should none of those slice (OCC), the
    next ones in order until one does."""
    coarse = [c for c in candidates if not c.exact]
    if not coarse:
        return candidates
    least = min(c.overhang for c in candidates)
    contenders = [c for c in coarse if c.overhang <= least + OVERHANG_TIE]
    if not contenders:
        if any(c.exact for c in candidates):
            # An exact candidate leaves less overhang than any coarse one, and overhang is
            # ranked first: none of these can win (the bottle's whole orientation was
            # sliced exactly for nothing, 3 s).
            return candidates
        contenders = coarse
    if _behind_exact(contenders, candidates, least, objective):
        # The decomposition of the table costs 8.5 % less time than its best whole
        # orientation for the same material: slicing that took 0.35 s of its 1.0 s choice.
        return candidates
    value = _objective(contenders, objective)
    best = min(value(c) for c in contenders)
    unit = _unit(objective, best)
    replaced: dict[int, Candidate | None] = {}
    mirrors: dict[int, Candidate] = {}      # left sampled, marked as mirrors
    lost: list[str] = []
    for c in sorted(contenders, key=value):
        near = value(c) <= best + max(COARSE_MARGIN, 0.0) * unit
        if not near and any(r is not None for r in replaced.values()):
            break
        mirrored = _mirror_costed(c, replaced.values())
        if mirrored:
            mirrors[id(c)] = dataclasses.replace(c, mirror_of=mirrored.label)
            continue
        twin = _as_twin(c, candidates)
        if twin is not None:
            # A decomposition that kept the solid whole along this very direction: the
            # same layers (the screw thread sliced its 71 layers twice, 50 s each).
            replaced[id(c)] = twin
            continue
        try:
            made = _exact(c.label, c.placed, c.plan, False, layer_settings, path_settings,
                          motion)
            replaced[id(c)] = c if made is None else dataclasses.replace(made,
                                                                         direction=c.direction)
        except GeometryError as exc:
            replaced[id(c)] = None     # its exact layers cannot be cut: not a plan
            lost.append(f"{c.label}: {exc}")
    result = [replaced.get(id(c), mirrors.get(id(c), c)) for c in candidates]
    if not any(c is not None and c.exact for c in result):
        raise PlanError("no candidate plan could be sliced: " + "; ".join(lost))
    return [c for c in result if c is not None]
