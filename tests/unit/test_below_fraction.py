"""The clipped-triangle fraction that every mesh overhang and area profile reads."""
import numpy as np
from shapely.geometry import Polygon

from freecad_conformal.geometry.surface_mesh import below_fraction, sorted_below_fraction


def clipped_fraction(values: np.ndarray) -> float:
    """Reference: the share of the unit triangle where the linear function with these corner
    values is negative, the triangle clipped by a large square on that side (shapely)."""
    g0, g1, g2 = values
    triangle = Polygon([(0, 0), (1, 0), (0, 1)])
    # f(u, v) = g0 + (g1 - g0) u + (g2 - g0) v < 0: cut the triangle by that half-plane.
    a, b = g1 - g0, g2 - g0
    if abs(a) < 1e-15 and abs(b) < 1e-15:
        return 1.0 if g0 < 0 else 0.0
    far = 10.0
    normal = np.array([a, b]) / np.hypot(a, b)
    along = np.array([-normal[1], normal[0]])
    # A point on the zero line, then a big square on its negative side.
    origin = -g0 * np.array([a, b]) / (a * a + b * b)
    corners = [origin + far * along, origin - far * along,
               origin - far * along - 2 * far * normal, origin + far * along - 2 * far * normal]
    half = Polygon(corners)
    return triangle.intersection(half).area / triangle.area


def test_matches_the_clipped_triangle_for_random_corner_values():
    rng = np.random.default_rng(7)
    values = rng.normal(size=(300, 3))
    values[:20] = np.abs(values[:20])           # wholly above
    values[20:40] = -np.abs(values[20:40])      # wholly below
    values[40:50, 1] = 0.0                      # a corner on the zero
    got = below_fraction(values)
    expected = np.array([clipped_fraction(v) for v in values])
    assert np.allclose(got, expected, atol=1e-9)
    assert np.all(got[:20] == 0.0) and np.all(got[20:40] == 1.0)


def test_corner_order_does_not_matter_and_sorted_input_agrees():
    rng = np.random.default_rng(3)
    values = rng.normal(size=(500, 3))
    permuted = values[:, [2, 0, 1]]
    ordered = np.sort(values, axis=1)
    assert np.array_equal(below_fraction(values), below_fraction(permuted))
    assert np.array_equal(below_fraction(values),
                          sorted_below_fraction(ordered[:, 0], ordered[:, 1], ordered[:, 2]))


def test_empty_input():
    assert below_fraction(np.zeros((0, 3))).shape == (0,)
