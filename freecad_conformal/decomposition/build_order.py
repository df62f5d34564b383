"""Build order of sub-parts: parents first, the larger free sub-part first (METHODS section
4), reordered among brothers so the tool envelope never meets what is already built."""
from __future__ import annotations

from freecad_conformal.errors import PlanError
from freecad_conformal.decomposition.subparts import SubPart


class BlockedOrder(PlanError):
    """No collision-free order: `blocked` maps each sub-part that could not be placed (its
    index) to the indices of those it would hit."""

    def __init__(self, message: str, blocked: dict[int, list[int]]) -> None:
        super().__init__(message)
        self.blocked = blocked


#: Orders explored before giving up on finding a collision-free one (the search backtracks;
#: a plan of a few dozen sub-parts stays far below this).
MAX_ORDERS_TRIED = 20000


def tool_envelope(tool):
    """The collision envelope of a tool id (from the library), a Tool, or an Envelope."""
    from freecad_conformal.process.tools import Envelope, Tool

    if isinstance(tool, Envelope):
        return tool
    if isinstance(tool, Tool):
        return tool.envelope
    from freecad_conformal.process.library import ToolLibrary

    return ToolLibrary.load().get(str(tool)).envelope


def build_order(subparts: list[SubPart], tool=None, notes: list[str] | None = None,
                checker=None, one_platform: bool = False) -> list[int]:
    """Indices of `subparts` in build order.

    Args:
        subparts: sub-parts with `parent` set (None for roots).
        tool: tool id / Tool / Envelope for the collision check; None skips the check.
        notes: receives a line when the order had to depart from the volume rule.
        checker: a prepared CollisionChecker (tests, reuse); built from `tool` otherwise.
        one_platform: the solids of a compound stand side by side on one platform
            (decomposition/layout.py), so what is built of the others is in the way too; by
            default each solid is its own tree on its own bed, as decompose plans them.
    Raises:
        BlockedOrder: no order builds every sub-part without a collision; the message
            names the sub-parts that could not be placed and what they hit.
    """
    preferred = _volume_order(subparts)
    if tool is None and checker is None:
        return preferred
    if checker is None:
        from freecad_conformal.geometry.collision import CollisionChecker

        checker = CollisionChecker([s.shape for s in subparts],
                                   [s.build_direction for s in subparts], tool_envelope(tool))
    order, blocked = _search(subparts, checker, one_platform)
    if order is None:
        detail = "; ".join(f"{subparts[i].name} (along {_dir(subparts[i])}) would hit "
                           + ", ".join(subparts[j].name for j in hits)
                           for i, hits in sorted(blocked.items()))
        raise BlockedOrder(f"no collision-free build order for {len(subparts)} sub-parts: "
                           f"{detail}", blocked)
    if notes is not None and order != preferred:
        notes.append("build order changed from largest-first to avoid tool collisions: "
                     + " ".join(subparts[i].name for i in order))
    return order


def _dir(subpart: SubPart) -> str:
    return "(" + ", ".join(f"{c:.3g}" for c in subpart.build_direction) + ")"


def _volume_order(subparts: list[SubPart]) -> list[int]:
    """Parents before children; among the sub-parts free to build, the largest first."""
    done: list[int] = []
    while len(done) < len(subparts):
        ready = [s for s in subparts if s.index not in done
                 and (s.parent is None or s.parent in done)]
        if not ready:
            raise PlanError("the sub-part tree has a cycle: "
                            + ", ".join(s.name for s in subparts if s.index not in done))
        done.append(max(ready, key=lambda s: (s.volume, -s.index)).index)
    return done


def _search(subparts: list[SubPart], checker,
            one_platform: bool) -> tuple[list[int] | None, dict[int, list[int]]]:
    """Depth-first search over orders, largest ready sub-part tried first."""
    blocked: dict[int, list[int]] = {}
    tried = 0

    def extend(done: list[int]) -> list[int] | None:
        nonlocal tried
        if len(done) == len(subparts):
            return done
        ready = sorted((s for s in subparts if s.index not in done
                        and (s.parent is None or s.parent in done)),
                       key=lambda s: (-s.volume, s.index))
        # The check let concurrent sub-parts pass each other because the toolpath builds
        # them together, layer by layer; it does so only for consecutive ones, so a ready
        # concurrent mate of the last one placed comes next.
        mates = [s for s in ready if done and checker.concurrent_with(done[-1], s.index)]
        for s in mates or ready:
            tried += 1
            if tried > MAX_ORDERS_TRIED:
                return None
            # Unless laid out on one platform, each solid of a compound is its own tree on
            # its own bed (decompose plans each root on the solid's lowest level), so only
            # its own sub-parts are in the way.
            hits = checker.hits(s.index, [i for i in done if one_platform
                                          or subparts[i].solid_index == s.solid_index])
            if hits:
                blocked.setdefault(s.index, sorted(set(blocked.get(s.index, [])) | set(hits)))
                continue
            found = extend(done + [s.index])
            if found is not None:
                return found
        return None

    return extend([]), blocked
