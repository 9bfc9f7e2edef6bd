"""`drape_garment`: settling a cloth on a still body (a real Newton simulation)."""

from __future__ import annotations

import numpy as np
import pytest

from data_prep.simulate.inside import signed_distance
from tests.data_prep.simulate.scenes import FPS, sphere, square


def test_drape_settles_a_cloth_on_a_still_sphere() -> None:
    """drape_garment: the cloth ends at rest on the sphere (centre on top, corners hanging,
    outside the body), and a later call from the drape hardly moves it."""
    from data_prep.simulate import drape_garment

    radius = 0.15
    body, body_faces = sphere(radius)
    pos, faces = square(cells=12, size=0.5, height=radius + 0.05)
    drape = drape_garment(pos, faces, body, body_faces, FPS, max_frames=60)
    final = drape.positions
    centre = np.argmin(np.linalg.norm(pos[:, :2], axis=1))
    corners = np.argsort(-np.linalg.norm(pos[:, :2], axis=1))[:4]
    assert final[centre, 2] == pytest.approx(radius, abs=0.015)
    assert (final[corners, 2] < final[centre, 2] - 0.05).all()
    assert (signed_distance(final, body, body_faces) > -0.01).all()
    assert drape.frames <= 60 and drape.mean_displacement > 0.02
    again = drape_garment(final, faces, body, body_faces, FPS, max_frames=10)
    assert np.linalg.norm(again.positions - final, axis=1).mean() < 0.5 * drape.mean_displacement
    with pytest.raises(ValueError, match="max_frames"):
        drape_garment(pos, faces, body, body_faces, FPS, max_frames=0)
