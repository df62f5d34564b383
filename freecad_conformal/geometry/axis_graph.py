"""The centroidal-axis graph: nodes (section centroids), links, branches and their relations.

Pure data (numpy only) so the slicer and the preview can read it without FreeCAD.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: Criterion 1 of METHODS section 3: a splitting face's normal within 10° of the link.
SPLIT_NORMAL_ANGLE = math.radians(10.0)

#: A section area growing or shrinking by more than this factor between two steps is a
#: sudden change (a cap on a column, a flange): the centroid may stay in line, so the
#: turn test cannot see it (the published method's blind spot).
BLIND_SPOT_RATIO = 1.5


@dataclass
class AxisNode:
    """A centroid of one section loop: `point` in 3D, the loop's `area`, its `branch`."""

    id: int
    point: np.ndarray
    area: float
    branch: int


@dataclass
class AxisLink:
    """A link between two nodes; kind is "continue", "turn" (new direction), "bend" (a true
    direction change under the break angle) or "join" (a branch merging into another);
    `is_break` marks a C1 break (direction change sharper than the break angle)."""

    start: int
    end: int
    kind: str
    is_break: bool = False


@dataclass
class AxisBranch:
    """A chain of nodes searched along one direction; `parent` is the father branch."""

    id: int
    direction: np.ndarray
    parent: int | None
    nodes: list[int] = field(default_factory=list)
    hanging: bool = False


@dataclass
class AxisGraph:
    """Nodes, links and branches of a centroidal axis, with father/child/brother relations."""

    method: str
    step: float
    nodes: list[AxisNode] = field(default_factory=list)
    links: list[AxisLink] = field(default_factory=list)
    branches: list[AxisBranch] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add_node(self, point: np.ndarray, area: float, branch: int) -> int:
        node = AxisNode(len(self.nodes), np.asarray(point, dtype=float), float(area), branch)
        self.nodes.append(node)
        self.branches[branch].nodes.append(node.id)
        return node.id

    def add_branch(self, direction: np.ndarray, parent: int | None, hanging: bool = False) -> int:
        self.branches.append(AxisBranch(len(self.branches), np.asarray(direction, dtype=float),
                                        parent, hanging=hanging))
        return len(self.branches) - 1

    def father(self, branch: int) -> int | None:
        return self.branches[branch].parent

    def children(self, branch: int) -> list[int]:
        return [b.id for b in self.branches if b.parent == branch]

    def brothers(self, branch: int) -> list[int]:
        parent = self.branches[branch].parent
        return [b.id for b in self.branches if b.parent == parent and b.id != branch]

    def link_vector(self, link: AxisLink) -> np.ndarray:
        return self.nodes[link.end].point - self.nodes[link.start].point

    def link_direction(self, link: AxisLink) -> np.ndarray | None:
        """Unit direction of a link; for a turn, the direction of the member it leads into."""
        if link.kind == "turn":
            vector = self.branches[self.nodes[link.end].branch].direction
        else:
            vector = self.link_vector(link)
        length = float(np.linalg.norm(vector))
        return vector / length if length > 0 else None

    def break_links(self) -> list[AxisLink]:
        return [link for link in self.links if link.is_break]

    def points(self) -> np.ndarray:
        return np.array([n.point for n in self.nodes]).reshape(-1, 3)

    def polylines(self) -> list[np.ndarray]:
        """One (N, 3) polyline per link, for preview."""
        return [np.array([self.nodes[l.start].point, self.nodes[l.end].point]) for l in self.links]

    def supports_split(self, normal: np.ndarray, boundary: np.ndarray) -> bool:
        """Criteria 1 and 3 of METHODS section 3 against any break link L.

        `boundary` holds points (N, 3) of the splitting face's outer boundary: its normal is
        within 10° of ±L, and an extreme projection of the boundary on L lies between the
        projections of the link's two centroids.
        """
        n = np.asarray(normal, dtype=float)
        for link in self.break_links():
            direction = self.link_direction(link)
            if direction is None:
                continue
            if math.acos(min(1.0, abs(float(n @ direction)))) > SPLIT_NORMAL_ANGLE:
                continue
            start = float(self.nodes[link.start].point @ direction)
            end = float(self.nodes[link.end].point @ direction)
            projections = np.asarray(boundary, dtype=float) @ direction
            low, high = min(start, end), max(start, end)
            if any(low <= p <= high for p in (projections.min(), projections.max())):
                return True
        return False

    def blind_spots(self, ratio: float = BLIND_SPOT_RATIO) -> list[AxisLink]:
        """Links along one branch where the section area jumps by more than `ratio` while
        the centroid moves sideways by less than one step: a sudden change of shape the
        centroidal axis does not show (flagged for the area-jump rule, METHODS section 4)."""
        flagged = []
        for link in self.links:
            a, b = self.nodes[link.start], self.nodes[link.end]
            if link.kind != "continue" or a.branch != b.branch or min(a.area, b.area) <= 0:
                continue
            if max(a.area, b.area) / min(a.area, b.area) <= ratio:
                continue
            d = self.branches[a.branch].direction
            shift = self.link_vector(link)
            sideways = float(np.linalg.norm(shift - (shift @ d) * d))
            if sideways < self.step:
                flagged.append(link)
        return flagged

    def to_dict(self) -> dict:
        return {
            "format": "conformal.axis/1", "method": self.method, "step": self.step,
            "nodes": [{"id": n.id, "point": [float(c) for c in n.point], "area": n.area,
                       "branch": n.branch} for n in self.nodes],
            "links": [{"start": l.start, "end": l.end, "kind": l.kind, "break": l.is_break}
                      for l in self.links],
            "branches": [{"id": b.id, "direction": [float(c) for c in b.direction],
                          "father": b.parent, "children": self.children(b.id),
                          "brothers": self.brothers(b.id), "nodes": list(b.nodes),
                          "hanging": b.hanging} for b in self.branches],
            "blind_spots": [{"start": l.start, "end": l.end,
                             "area_ratio": _ratio(self.nodes[l.start].area, self.nodes[l.end].area)}
                            for l in self.blind_spots()],
            "notes": list(self.notes),
        }


def _ratio(a: float, b: float) -> float:
    return float(max(a, b) / min(a, b))
