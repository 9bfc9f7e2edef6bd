"""`signed_distance`: the independent inside-the-body measure."""

from __future__ import annotations

import numpy as np

from data_prep.simulate.inside import signed_distance
from tests.data_prep.simulate.scenes import sphere


def test_signed_distance_to_a_sphere() -> None:
    radius = 0.2
    vertices, faces = sphere(radius, subdivisions=4)
    rng = np.random.default_rng(0)
    direction = rng.normal(size=(200, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    scale = rng.uniform(0.3, 1.7, size=200)
    depth = signed_distance(direction * (radius * scale)[:, None], vertices, faces)
    # Exact up to the tessellation (the icosphere's faces lie < 1 mm inside the sphere).
    np.testing.assert_allclose(depth, radius * (scale - 1), atol=1.5e-3)
    clear = np.abs(scale - 1) > 0.02  # farther from the surface than the tessellation error
    assert ((depth < 0) == (scale < 1))[clear].all()
