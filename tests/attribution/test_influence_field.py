"""The influence-field measure on graphs whose answers are known by hand."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.attribution import geodesic_region, hop_distances, influence_field, mass_profile


def path(n: int = 10, spacing: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Vertices on the x axis, each joined to the next (both directions)."""
    pos = np.column_stack([np.arange(n) * spacing, np.zeros(n), np.zeros(n)])
    a = np.arange(n - 1)
    return pos, np.vstack([np.concatenate([a, a + 1]), np.concatenate([a + 1, a])])


def test_hand_computed_field() -> None:
    pos, edges = path()
    heat = np.zeros(10)
    heat[[0, 1, 2]] = [8.0, 1.0, 1.0]
    field = influence_field(heat, pos, edges, 0, mass=0.9)
    # 8 + 1 = 9 = 90% of 10: two vertices, one hop, 0.1 m.
    assert (field.count, field.hops, field.support, field.support_hops) == (2, 1, 3, 2)
    assert field.radius == pytest.approx(0.1)
    assert field.total == 10.0
    whole = influence_field(heat, pos, edges, 0, mass=1.0)
    assert (whole.count, whole.hops) == (3, 2)
    assert whole.radius == pytest.approx(0.2)


def test_field_of_a_point_and_of_uniform_heat() -> None:
    pos, edges = path()
    point = np.zeros(10)
    point[4] = 2.0
    field = influence_field(point, pos, edges, 4)
    assert (field.count, field.hops, field.radius, field.support) == (1, 0, 0.0, 1)
    uniform = influence_field(np.ones(10), pos, edges, 0, mass=0.9)
    assert (uniform.count, uniform.hops) == (9, 8)


def test_region_sources_and_floor() -> None:
    pos, edges = path()
    heat = np.array([1.0, 0, 0, 0, 0, 0, 0, 0, 0, 1.0]) + 1e-6
    field = influence_field(heat, pos, edges, np.array([0, 9]), mass=0.9)
    assert field.hops == 0 and field.count == 2
    assert influence_field(heat, pos, edges, 0, floor=0.0).support == 10
    assert influence_field(heat, pos, edges, 0, floor=1e-3).support == 2


def test_disconnected_mass_has_infinite_radius() -> None:
    pos, edges = path(4)
    pos = np.vstack([pos, [[5.0, 0.0, 0.0]]])          # vertex 4: no edges
    heat = np.array([1.0, 0.0, 0.0, 0.0, 9.0])
    field = influence_field(heat, pos, edges, 0)
    assert field.radius == np.inf and field.hops == -1 and field.support_hops == -1


def test_hops_profile_and_region() -> None:
    pos, edges = path()
    np.testing.assert_array_equal(hop_distances(edges, 10, np.array([3])),
                                  np.abs(np.arange(10) - 3))
    profile = mass_profile(np.ones(10), np.arange(10.0), np.array([-1, 0, 4, 100]))
    np.testing.assert_allclose(profile, [0.0, 0.1, 0.5, 1.0])
    np.testing.assert_array_equal(geodesic_region(pos, edges, 5, 0.15), [4, 5, 6])
    np.testing.assert_array_equal(geodesic_region(pos, edges, [0, 9], 0.0), [0, 9])


@pytest.mark.parametrize(("heat", "kwargs", "message"), [
    (-np.ones(10), {}, "non-negative"),
    (np.zeros(10), {}, "zero everywhere"),
    (np.ones(10), {"mass": 0.0}, r"mass must be in \(0, 1\]"),
    (np.ones(10), {"mass": 1.5}, r"mass must be in \(0, 1\]"),
    (np.ones(10), {"floor": 1.0}, r"floor must be in \[0, 1\)"),
    (np.ones(10), {"sources": 10}, "sources must be vertex indices in 0..9"),
    (np.ones((10, 1)), {}, r"heat must have shape \(N,\)"),
])
def test_bad_inputs(heat, kwargs, message) -> None:
    pos, edges = path()
    arguments = {"sources": 0} | kwargs
    with pytest.raises(ValueError, match=message):
        influence_field(heat, pos, edges, **arguments)


def test_bad_region_radius() -> None:
    pos, edges = path()
    with pytest.raises(ValueError, match="radius must be >= 0"):
        geodesic_region(pos, edges, 0, -1.0)
