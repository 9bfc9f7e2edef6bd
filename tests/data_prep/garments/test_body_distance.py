"""`BodyDistance`: the exact signed distance to the body the generator checks against."""

from __future__ import annotations

import numpy as np

from data_prep.garments.body_distance import BodyDistance


def test_body_distance_on_a_sphere() -> None:
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.2)
    distance = BodyDistance(sphere.vertices, sphere.faces)
    rng = np.random.default_rng(0)
    points = rng.uniform(-0.35, 0.35, (2000, 3))
    signed = distance(points)
    exact = np.linalg.norm(points, axis=1) - 0.2
    np.testing.assert_allclose(signed, exact, atol=2e-3)  # chordal error of the mesh
    inside, bound = distance.clearance(points, threshold=0.05)
    far = np.abs(exact) > 3e-3
    assert np.array_equal(inside[far], exact[far] < 0)
    assert (bound <= np.abs(signed) + 1e-12).all()
    # Two overlapping spheres: the union's distance is the minimum.
    shifted = np.asarray(sphere.vertices) + np.array([0.3, 0.0, 0.0])
    union = BodyDistance(np.concatenate([sphere.vertices, shifted]),
                         np.concatenate([sphere.faces, sphere.faces + len(sphere.vertices)]))
    both = np.minimum(exact, np.linalg.norm(points - [0.3, 0, 0], axis=1) - 0.2)
    np.testing.assert_allclose(union(points), both, atol=2e-3)
