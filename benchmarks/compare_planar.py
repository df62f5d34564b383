"""Support-free multi-axis plan against PrusaSlicer (planar, with and without supports).

For each part: export STL, slice it with PrusaSlicer's CLI in each of the six axis-aligned
orientations with supports on, keep its best (least filament), slice that orientation again
with supports off, and read filament volume, support-only extrusion (";TYPE:Support
material" and its interface) and estimated time from the G-code. Then plan the part with
this project (decomposition, layers, paths) at the same settings and print both with ratios.
Last, PrusaSlicer slices each of our sub-parts stood on its base: the same support-free
geometry under the same rules, which separates what the geometry costs from what our paths do.
Then issue 16's goal for each part, and whether the plan meets it: a part PrusaSlicer prints
without support in one of those orientations is held to that print, the others to its print
with supports (`goal_verdict`).

The same rules on both sides, passed to PrusaSlicer explicitly (`PRUSA_SETTINGS`) and to the
planner (`plan_options`): layer 0.2 mm (the first one too), nozzle 0.4 mm, bead width 0.45 mm
for every role (PrusaSlicer's automatic width), rounded beads (PrusaSlicer's model,
`paths.bead`), 2 perimeters, 20 % rectilinear infill reaching 25 % into the perimeters,
sparse pieces under 70 mm² printed solid, three solid top/bottom layers, no skirt, speeds per
role (external perimeter 30, perimeters 60, perimeter loops up to 2π·6.5 mm 15, sparse
infill 80, solid and top infill 20, travel 130 mm/s, the first layer at the same speeds), the time estimate's limits
(acceleration 1500 mm/s², jerk 10 mm/s) and the cooling slowdown (layers under 5 s, not
below 10 mm/s), support where a print leaves overhang (2.5 mm between lines, three interface
layers on top and at a foot on the part, 60 mm/s, a 0.2 mm contact gap, none under bridges:
`plan --support` on ours). Bridges
over unsupported areas: both lay them apart from anchor to anchor, ours by
`scan.bridge_angle`, PrusaSlicer's by its bridge detector, with thick round beads. What only PrusaSlicer does: retraction (its estimate counts it; our toolpath has none). Where a perimeter loop has no
room we lay gap fill, as PrusaSlicer's classic perimeter generator does; its default one
(Arachne, used here) widens the loops instead.

`--roles` also prints material and time per role on both sides (PrusaSlicer's ;TYPE:
blocks, timed with this project's model; our toolpath's roles).

Needs the Debian package prusa-slicer (`TMPDIR=/var/tmp apt-get install -y prusa-slicer`).
Run: `.venv/bin/python benchmarks/compare_planar.py [--roles] [jack bracket hinge CrankArm]`
(names of samples or shared parts, or .brep/.step files of your own).
"""
from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from freecad_conformal.errors import ConformalError  # noqa: E402
from freecad_conformal.geometry import samples  # noqa: E402
from freecad_conformal.geometry.solids import load_shape  # noqa: E402
from freecad_conformal.paths.timing import (estimate_time, junction_speeds, move_seconds,  # noqa: E402
                                            move_times)
from freecad_conformal.jobs.job import plan_job  # noqa: E402
from freecad_conformal.jobs.plan import PlanOptions  # noqa: E402
from freecad_conformal.toolpath import KINDS  # noqa: E402

PARTS_DIR = ROOT.parent / "shared" / "parts"
LAYER, NOZZLE, PERIMETERS, INFILL, BEAD = 0.2, 0.4, 2, 0.20, 0.45
#: PrusaSlicer 2.5 defaults (mm/s) and its time-estimate machine limits.
SPEEDS = {"external_perimeter": 30.0, "perimeter": 60.0, "infill": 80.0, "solid_infill": 20.0,
          "travel": 130.0, "small_perimeter": 15.0, "bridge_infill": 60.0, "support": 60.0}
#: Support where a print needs it (PrusaSlicer's defaults, stated): 2.5 mm between lines, three
#: solid interface layers at the support's speed on top of a column and at its foot where
#: it stands on the part, a 0.2 mm contact gap, none under what a bridge spans (its
#: defaults: bottom interface layers as the top's, "Don't support bridges"; `paths.support`).
SUPPORT_SPACING, SUPPORT_INTERFACE_LAYERS = 2.5, 3
ACCELERATION, JERK = 1500.0, 10.0
INFILL_OVERLAP, SOLID_BELOW_AREA, SOLID_LAYERS, MIN_LAYER_TIME, MIN_SPEED = 0.25, 70.0, 3, 5.0, 10.0
#: Every PrusaSlicer setting that the comparison depends on, stated rather than defaulted.
PRUSA_SETTINGS = [
    "--layer-height", str(LAYER), "--first-layer-height", str(LAYER),
    "--nozzle-diameter", str(NOZZLE), "--extrusion-width", str(BEAD),
    *[arg for role in ("first-layer", "external-perimeter", "perimeter", "infill", "solid-infill",
                       "top-infill", "support-material")
      for arg in (f"--{role}-extrusion-width", str(BEAD))],
    "--perimeters", str(PERIMETERS), "--top-solid-layers", str(SOLID_LAYERS),
    "--bottom-solid-layers", str(SOLID_LAYERS), "--fill-density", f"{INFILL * 100:g}%",
    "--fill-pattern", "rectilinear", "--infill-overlap", f"{INFILL_OVERLAP * 100:g}%",
    "--solid-infill-below-area", f"{SOLID_BELOW_AREA:g}", "--skirts", "0",
    "--external-perimeter-speed", f"{SPEEDS['external_perimeter']:g}",
    "--perimeter-speed", f"{SPEEDS['perimeter']:g}",
    "--small-perimeter-speed", f"{SPEEDS['small_perimeter']:g}", "--infill-speed", f"{SPEEDS['infill']:g}",
    "--solid-infill-speed", f"{SPEEDS['solid_infill']:g}",
    "--top-solid-infill-speed", f"{SPEEDS['solid_infill']:g}", "--travel-speed", f"{SPEEDS['travel']:g}",
    "--bridge-speed", f"{SPEEDS['bridge_infill']:g}",
    "--support-material-speed", f"{SPEEDS['support']:g}",
    "--support-material-interface-speed", "100%",
    "--support-material-spacing", f"{SUPPORT_SPACING:g}",
    "--support-material-interface-layers", str(SUPPORT_INTERFACE_LAYERS),
    "--support-material-bottom-interface-layers", "-1",
    "--support-material-contact-distance", str(LAYER), "--dont-support-bridges",
    "--first-layer-speed", "100%", "--slowdown-below-layer-time", f"{MIN_LAYER_TIME:g}",
    "--min-print-speed", f"{MIN_SPEED:g}", "--use-relative-e-distances"]
ORIENTATIONS = {"as modelled": [], "rotate-x 90": ["--rotate-x", "90"],
                "rotate-x 180": ["--rotate-x", "180"], "rotate-x -90": ["--rotate-x", "-90"],
                "rotate-y 90": ["--rotate-y", "90"], "rotate-y -90": ["--rotate-y", "-90"]}
FILAMENT_AREA = math.pi * 1.75 ** 2 / 4.0


@dataclass
class Slice:
    orientation: str
    volume_cm3: float
    support_cm3: float
    seconds: float
    gcode: Path


def parse_time(text: str) -> float:
    match = re.search(r"estimated printing time \(normal mode\) = (.*)", text)
    units = {"d": 86400, "h": 3600, "m": 60, "s": 1}
    return float(sum(int(n) * units[u] for n, u in re.findall(r"(\d+)([dhms])", match.group(1))))


def support_volume(text: str) -> float:
    """cm³ extruded in ;TYPE:Support material (and interface) blocks (relative E): moves
    that lay a bead only, not the filament pushed back after a retraction (`G1 E2`, no X
    or Y: on the jack 192 of them, 0.9 cm³ counted as support before)."""
    total, inside = 0.0, False
    for line in text.splitlines():
        if line.startswith(";TYPE:"):
            inside = line.startswith(";TYPE:Support material")
        elif (inside and line.startswith("G1") and " E" in line
              and (" X" in line or " Y" in line)):
            value = float(line.split(" E")[1].split()[0])
            total += max(value, 0.0)
    return total * FILAMENT_AREA / 1000.0


def prusa_slice(stl: Path, orientation: str, supports: bool, work: Path) -> Slice:
    out = work / f"{stl.stem}_{orientation.replace(' ', '_')}_{int(supports)}.gcode"
    command = ["prusa-slicer", "--export-gcode", *PRUSA_SETTINGS, "--center", "100,100",
               *ORIENTATIONS[orientation], "-o", str(out), str(stl)]
    if supports:
        command.insert(2, "--support-material")
    subprocess.run(command, check=True, capture_output=True, timeout=1800)
    text = out.read_text()
    volume = float(re.search(r"filament used \[cm3\] = ([\d.]+)", text).group(1))
    return Slice(orientation, volume, support_volume(text), parse_time(text), out)


def try_slice(stl: Path, orientation: str, supports: bool, work: Path) -> Slice | None:
    """`prusa_slice`, or None where PrusaSlicer refuses (the screw lying on its side without
    supports: "no extrusions in the first layer")."""
    try:
        return prusa_slice(stl, orientation, supports, work)
    except subprocess.CalledProcessError:
        return None


def planar_baselines(stl: Path, work: Path) -> tuple[Slice, Slice | None, bool]:
    """PrusaSlicer's best orientation with supports (least filament), its best support-free
    print, and whether the part has one: the least filament among orientations its
    supported slice needs no support in, sliced with supports off; else the best orientation
    with supports off (a print that sags, for reference); None if PrusaSlicer refuses that
    too."""
    with_support = [s for s in (try_slice(stl, o, True, work) for o in ORIENTATIONS) if s]
    if not with_support:
        raise SystemExit(f"PrusaSlicer sliced {stl.name} in no orientation")
    best = min(with_support, key=lambda s: s.volume_cm3)
    free = sorted((s for s in with_support if s.support_cm3 <= 0), key=lambda s: s.volume_cm3)
    for candidate, support_free in [*((s, True) for s in free), (best, False)]:
        bare = try_slice(stl, candidate.orientation, False, work)
        if bare is not None:
            return best, bare, support_free
    return best, None, False


def prusa_on_subparts(plan, work: Path) -> Slice:
    """PrusaSlicer (supports off) on each of our sub-parts stood on its base, summed: the same
    support-free geometry under the same rules, so what differs from our figures is the path
    planning alone (and PrusaSlicer's bottom skins on sub-parts that rest on a parent)."""
    import FreeCAD as App

    volume = seconds = 0.0
    for sub in plan.ordered():
        shape = sub.shape.copy()
        shape.rotate(App.Vector(0, 0, 0), App.Vector(*sub.rotation_axis), math.degrees(sub.rotation_angle))
        turned = App.Rotation(App.Vector(*sub.rotation_axis), math.degrees(sub.rotation_angle))
        up = turned.multVec(App.Vector(*sub.build_direction))
        assert abs(up.z - 1.0) < 1e-9, f"{sub.name} turned to {up}, not +Z"
        stl = work / f"{sub.name}.stl"
        shape.exportStl(str(stl))
        try:
            result = prusa_slice(stl, "as modelled", False, work)
        except subprocess.CalledProcessError as exc:
            # e.g. a sub-part too thin for PrusaSlicer to slice: say so, keep the others
            reason = (exc.stderr or b"").decode(errors="replace").strip().splitlines()
            print(f"  PrusaSlicer could not slice sub-part {sub.name}: "
                  f"{reason[-1] if reason else 'exit ' + str(exc.returncode)}", flush=True)
            continue
        volume += result.volume_cm3
        seconds += result.seconds
    return Slice("our sub-parts", volume, 0.0, seconds, work)


def capped_column():
    """A part of our own making (no test uses it): a 12 mm column 30 mm tall under a round
    30 mm cap, 6 mm thick. Support-free upside down, as a planar slicer prints it."""
    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    column = Part.makeCylinder(6.0, 30.0)
    cap = Part.makeCylinder(15.0, 6.0, App.Vector(0, 0, 30.0))
    return column.fuse(cap).removeSplitter().Solids[0]


def u_channel():
    """Issue 16's U-channel with inward lips (no test of this file uses it; the one in
    tests/geometry/test_decompose.py is its twin): 40 mm long, 30 x 20 mm across, walls
    5 mm, lips 5 mm over a 10 mm gap. It needs no support standing on an end or a side."""
    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    V = App.Vector
    channel = Part.makeBox(40, 30, 20)
    channel = channel.cut(Part.makeBox(40, 20, 12, V(0, 5, 4)))
    return channel.cut(Part.makeBox(40, 10, 4, V(0, 10, 16))).removeSplitter().Solids[0]


def spool():
    """A spool of our own making (tests/geometry/test_decompose.py's twin, with six bolt
    holes): a tube r 15 / 12, 60 mm long, with a flange r 30 x 5 mm at each end, each with
    six r 3 holes on a 23 mm circle. Its upper flange overhangs the tube all round; it needs
    support in every orientation."""
    import math

    from freecad_conformal.freecad_env import import_freecad

    App, Part = import_freecad()
    V = App.Vector
    flange = Part.makeCylinder(30, 5).cut(Part.makeCylinder(12, 5))
    for k in range(6):
        turn = 2 * math.pi * k / 6
        flange = flange.cut(Part.makeCylinder(3, 5, V(23 * math.cos(turn), 23 * math.sin(turn), 0)))
    tube = Part.makeCylinder(15, 60).cut(Part.makeCylinder(12, 60))
    return tube.fuse([flange, flange.translated(V(0, 0, 55))]).removeSplitter().Solids[0]


#: Parts made here for the comparison, beside the samples and ../shared/parts.
OWN_PARTS = {"capped_column": capped_column, "u_channel": u_channel, "spool": spool}


def load(name: str):
    name = name.removeprefix("sample:")     # as `plan` names the samples
    if name in samples.SAMPLES:
        return samples.SAMPLES[name]()
    if name in OWN_PARTS:
        return OWN_PARTS[name]()
    for suffix in (".brep", ".step"):
        if (PARTS_DIR / f"{name}{suffix}").exists():
            return load_shape(PARTS_DIR / f"{name}{suffix}")
    if Path(name).suffix.lower() in (".brep", ".brp", ".step", ".stp") and Path(name).is_file():
        return load_shape(name)     # a part of the user's own making
    raise SystemExit(f"no part named {name!r}: a sample ({', '.join(samples.SAMPLES)}), "
                     f"{', '.join(OWN_PARTS)}, a .brep/.step in {PARTS_DIR}, or a .brep/.step file")


def prusa_roles(gcode: Path) -> dict[str, list[float]]:
    """{role: [mm, mm³, s]} of a PrusaSlicer G-code (";TYPE:" blocks, relative E), timed with
    this project's model; travel as "travel", filament-only moves (retraction) as "retract"."""
    x = y = z = feed = 0.0
    role, moves, retract = "none", [], 0.0
    for line in gcode.read_text().splitlines():
        if line.startswith(";TYPE:"):
            role = line[6:].strip()
            continue
        if not line.startswith(("G1 ", "G0 ")):
            continue
        words = {w[0]: float(w[1:]) for w in line.split(";")[0].split()[1:] if w[0] in "XYZEF"}
        feed = words.get("F", feed * 60.0) / 60.0
        target = (words.get("X", x), words.get("Y", y), words.get("Z", z))
        e = words.get("E", 0.0)
        if target == (x, y, z):
            retract += abs(e) / feed if e else 0.0
            continue
        moves.append(((x, y, z), target, feed, role if e > 0 else "travel", max(e, 0.0)))
        x, y, z = target
    start = np.array([m[0] for m in moves])
    steps = np.array([m[1] for m in moves]) - start
    lengths = np.linalg.norm(steps, axis=1)
    speeds = np.array([m[2] for m in moves])
    seconds = move_times(lengths, speeds, junction_speeds(steps / lengths[:, None], speeds, JERK),
                         ACCELERATION)
    roles: dict[str, list[float]] = defaultdict(lambda: [0.0, 0.0, 0.0])
    for move, length, t in zip(moves, lengths, seconds):
        row = roles[move[3]]
        row[0] += length
        row[1] += move[4] * FILAMENT_AREA
        row[2] += t
    roles["retract"][2] += retract
    return dict(roles)


def our_roles(result) -> dict[str, list[float]]:
    """{role: [mm, mm³, s]} of a plan, timed as `ours` times it."""
    tp = result.assembly.toolpath
    deposits = np.flatnonzero(tp.kind == KINDS.index("deposit"))
    paths = dict(zip(deposits.tolist(), result.assembly.paths))
    roles: dict[str, list[float]] = defaultdict(lambda: [0.0, 0.0, 0.0])
    seconds, segments = move_seconds(tp, ACCELERATION, JERK)
    for t, segment in zip(seconds, segments.tolist()):
        roles[paths[segment].role if segment in paths else "travel"][2] += t
    for segment, path in paths.items():
        roles[path.role][0] += path.length
        roles[path.role][1] += path.length * float(tp.flow[segment])
    for points in result.assembly.travels:
        roles["travel"][0] += float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
    return dict(roles)


def print_roles(name: str, theirs: dict, mine: dict) -> None:
    print(f"\n{name}: per role (PS = PrusaSlicer supports off)")
    print(f"  {'role':<22} {'PS m':>7} {'PS cm3':>7} {'PS min':>7} | {'ours m':>7} {'cm3':>7} {'min':>7}")
    for role, row in sorted(theirs.items(), key=lambda kv: -kv[1][1]):
        print(f"  PS {role:<19} {row[0] / 1000:>7.1f} {row[1] / 1000:>7.3f} {row[2] / 60:>7.1f} |")
    for role, row in sorted(mine.items(), key=lambda kv: -kv[1][1]):
        print(f"  ours {role:<17} {'':>7} {'':>7} {'':>7} | {row[0] / 1000:>7.1f} {row[1] / 1000:>7.3f} "
              f"{row[2] / 60:>7.1f}")


def plan_options() -> PlanOptions:
    """The planner's side of PRUSA_SETTINGS, as a user gives it: plan settings
    (settings/plan.py), each also a `plan` flag and a Job property."""
    from freecad_conformal.jobs.options import plan_options as from_settings

    values = {"layer_height": LAYER, "bead_width": BEAD, "perimeters": PERIMETERS,
              "infill": INFILL * 100.0, "bead_model": "rounded",
              "infill_overlap": INFILL_OVERLAP * 100.0, "solid_below_area": SOLID_BELOW_AREA,
              "solid_layers": SOLID_LAYERS, "min_layer_time": MIN_LAYER_TIME,
              "min_speed": MIN_SPEED, "jerk": JERK, "support": True,
              "support_spacing": SUPPORT_SPACING,
              "support_interface_layers": SUPPORT_INTERFACE_LAYERS, "support_bridges": False,
              "support_bottom_interface_layers": -1,
              **{f"{role}_speed": speed for role, speed in SPEEDS.items()}}
    return from_settings(values)


def ours(shape, name: str):
    options = plan_options()
    started = time.perf_counter()
    result = plan_job(shape, options, part=name)
    seconds = estimate_time(result.assembly.toolpath, ACCELERATION, JERK)
    return result, seconds, time.perf_counter() - started


#: Issue 16's goals: against PrusaSlicer's support-free print where the part has one (material
#: and time), else against its print with supports in its best orientation.
SUPPORT_FREE_GOAL = (1.00, 1.00)
SUPPORTED_GOAL = (0.60, 0.70)


#: Overhang (mm²) our plan may leave and still count as support-free: the measure's noise
#: (`decomposition.decompose.TURN_SAVING`).
OUR_SUPPORT_FREE = 1.0


def goal_verdict(best: Slice, bare: Slice | None, support_free: bool, ours_cm3: float,
                 our_seconds: float, our_overhang: float = 0.0) -> str:
    """Which of issue 16's goals applies to the part, and whether our plan meets it. For a part
    that needs support, also the support's share of PrusaSlicer's material and the ratios of
    its own print with the support taken away: how far removing the support, and nothing
    else, goes toward the goal. A plan that leaves overhang without support under it
    (`our_overhang`, mm²) misses them, whatever its ratios (PrusaSlicer's count its
    support); where the plan prints support (`--support`), its material and time count it."""
    if support_free and bare is not None:
        material, seconds = ours_cm3 / bare.volume_cm3, our_seconds / bare.seconds
        goal, against = SUPPORT_FREE_GOAL, f"PS support-free ({bare.orientation})"
    else:
        material, seconds = ours_cm3 / best.volume_cm3, our_seconds / best.seconds
        goal, against = SUPPORTED_GOAL, f"PS with supports ({best.orientation})"
    met = material <= goal[0] and seconds <= goal[1] and our_overhang <= OUR_SUPPORT_FREE
    text = (f"vs {against}: material {material:.3f} (goal {goal[0]:.2f}), time {seconds:.3f} "
            f"(goal {goal[1]:.2f}): {'met' if met else 'missed'}")
    if our_overhang > OUR_SUPPORT_FREE:
        text += f" (our plan leaves {our_overhang:.0f} mm² of overhang without support)"
    if not support_free and bare is not None:
        text += (f"; support is {best.support_cm3 / best.volume_cm3:.0%} of its material; "
                 f"its print without the support: {bare.volume_cm3 / best.volume_cm3:.3f}, "
                 f"{bare.seconds / best.seconds:.3f}")
    return text


def unsupported(result) -> float:
    """The overhang (mm²) our plan leaves with no support printed under it and no bridge
    over it: all it leaves where it prints none and bridges none (a note names any columns
    `plan --support` had to leave out; a sealed cavity's ceiling is bridged, as
    PrusaSlicer bridges it)."""
    bridged = result.assembly.bridged_area > 0
    return result.plan.support_area if result.support_volume <= 0 and not bridged else 0.0


def _our_support(result) -> str:
    area = result.plan.support_area
    if area <= 0:
        return "none"
    if result.support_volume > 0:
        return f"{area:.0f} mm2 on {result.support_volume / 1000:.2f} cm3"
    return f"{area:.0f} mm2 bridged" if result.assembly.bridged_area > 0 else f"{area:.0f} mm2 bare"


def hms(seconds: float) -> str:
    whole = int(round(seconds))
    return f"{whole // 3600}h{whole // 60 % 60:02d}m"


def main(names: list[str], roles: bool = False) -> int:
    if shutil.which("prusa-slicer") is None:
        print("prusa-slicer is not installed: TMPDIR=/var/tmp apt-get install -y prusa-slicer")
        return 2
    rows = []
    # Every name is read before any part is planned: a misspelt last one lost the whole run.
    shapes = {given: load(given) for given in names}
    with tempfile.TemporaryDirectory(prefix="compare_planar_") as folder:
        work = Path(folder)
        for given in names:
            shape = shapes[given]
            name = Path(given.removeprefix("sample:")).stem   # a file's; else as given
            stl = work / f"{name}.stl"
            shape.exportStl(str(stl))
            best, bare, support_free = planar_baselines(stl, work)
            try:
                result, our_time, wall = ours(shape, name)
            except ConformalError as exc:
                print(f"{name}: no plan for {PlanOptions().machine}: {exc}", flush=True)
                continue
            parts_dir = work / f"{name}_subparts"
            parts_dir.mkdir()
            pieces = prusa_on_subparts(result.plan, parts_dir)
            rows.append((name, best, bare, result, our_time, pieces, support_free))
            print(f"{name}: {len(result.subparts)} sub-parts, planned in {wall:.1f} s", flush=True)
            if roles and bare is not None:
                print_roles(name, prusa_roles(bare.gcode), our_roles(result))
    print()
    print(f"{'part':<14} {'PS+sup orient.':<14} {'PS-sup orient.':<14} {'PS+sup cm3':>10} "
          f"{'sup cm3':>8} {'PS-sup cm3':>10} {'ours cm3':>9} {'ours/PS-sup':>11} {'ours/PS+sup':>11} | "
          f"{'PS+sup':>7} {'PS-sup':>7} {'ours':>7} {'t/PS-sup':>8} {'t/PS+sup':>8} | "
          f"{'our support':>11}")
    for name, best, bare, result, our_time, *_ in rows:
        ours_cm3 = result.material_volume / 1000.0
        free_orientation = bare.orientation if bare is not None else "(refused)"
        free_cm3 = f"{bare.volume_cm3:>10.2f}" if bare is not None else f"{'-':>10}"
        free_ratio = f"{ours_cm3 / bare.volume_cm3:>11.3f}" if bare is not None else f"{'-':>11}"
        free_t = f"{hms(bare.seconds):>7}" if bare is not None else f"{'-':>7}"
        free_t_ratio = f"{our_time / bare.seconds:>8.3f}" if bare is not None else f"{'-':>8}"
        print(f"{name:<14} {best.orientation:<14} {free_orientation:<14} {best.volume_cm3:>10.2f} "
              f"{best.support_cm3:>8.2f} {free_cm3} {ours_cm3:>9.2f} {free_ratio} "
              f"{ours_cm3 / best.volume_cm3:>11.3f} | {hms(best.seconds):>7} {free_t} "
              f"{hms(our_time):>7} {free_t_ratio} {our_time / best.seconds:>8.3f} | "
              f"{_our_support(result):>11}")
    print("\nPrusaSlicer without supports on each of our sub-parts, stood on its base (the same "
          "support-free geometry under the same rules; the difference is path planning):")
    print(f"{'part':<10} {'sub-parts':>9} {'PS cm3':>10} {'ours/PS':>8} | {'PS t':>7} {'t ours/PS':>9}")
    for name, _, _, result, our_time, pieces, _ in rows:
        if pieces.volume_cm3 <= 0 or pieces.seconds <= 0:
            print(f"{name:<10} {len(result.plan.subparts):>9}   (PrusaSlicer sliced none of them)")
            continue
        print(f"{name:<10} {len(result.plan.subparts):>9} {pieces.volume_cm3:>10.2f} "
              f"{result.material_volume / 1000.0 / pieces.volume_cm3:>8.3f} | {hms(pieces.seconds):>7} "
              f"{our_time / pieces.seconds:>9.3f}")
    print("\nIssue 16's goals (a part PrusaSlicer prints support-free in some orientation "
          "against that print, else against its print with supports):")
    for name, best, bare, result, our_time, _, support_free in rows:
        print(f"{name:<14} " + goal_verdict(best, bare, support_free,
                                            result.material_volume / 1000.0, our_time,
                                            unsupported(result)))
    print("\nPS = PrusaSlicer (its estimate); ours = plan material (rounded bead x length) and the "
          "same time model (trapezoids, jerk 10 mm/s, acceleration 1500 mm/s2, 5 s layer cooling)")
    return 0


if __name__ == "__main__":
    arguments = [a for a in sys.argv[1:] if a != "--roles"]
    sys.exit(main(arguments or ["jack", "bracket", "hinge", "CrankArm"], roles="--roles" in sys.argv))
