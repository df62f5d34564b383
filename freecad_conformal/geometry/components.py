"""Connected components of a graph given as edge arrays, in numpy (no scipy: FreeCAD's Addon
Manager installs only allow-listed packages, and scipy is not one)."""
from __future__ import annotations

import numpy as np


def connected_labels(count: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per node 0..count-1, a label shared by exactly the nodes connected to it through the
    edges (a[i], b[i]); labels are 0..k-1.

    Each round hooks the larger of an edge's two roots under the smaller, then compresses
    every path to its root (pointer jumping): a few rounds for a mesh's thousands of
    triangles."""
    parent = np.arange(count)
    a = np.asarray(a, dtype=np.int64)
    b = np.asarray(b, dtype=np.int64)
    while True:
        ra, rb = parent[a], parent[b]
        differ = ra != rb
        if not differ.any():
            break
        low, high = np.minimum(ra, rb)[differ], np.maximum(ra, rb)[differ]
        np.minimum.at(parent, high, low)
        while True:
            jumped = parent[parent]
            if np.array_equal(jumped, parent):
                break
            parent = jumped
    return np.unique(parent, return_inverse=True)[1].reshape(-1)
