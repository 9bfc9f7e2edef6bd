"""The stand-alone cone skirt (`flared_skirt`, used by the demo and benchmarks)."""

from __future__ import annotations

import numpy as np

from data_prep.garments import flared_skirt
from gnngarment.geometry import (
    check_mesh,
    connected_components,
    edge_index_from_faces,
    vertex_normals,
)


def test_flared_skirt_is_a_clean_outward_facing_tube() -> None:
    pos, faces = flared_skirt(1500, waist_radius=0.15, hem_radius=0.4, length=0.5, seed=3)
    report = check_mesh(pos, faces)
    assert report.ok and not report.findings, report.errors + report.findings
    assert abs(len(pos) - 1500) < 20
    assert connected_components(edge_index_from_faces(faces, len(pos)), len(pos)).max() == 0
    radial = pos[:, :2] / np.linalg.norm(pos[:, :2], axis=1, keepdims=True)
    assert (np.einsum("ij,ij->i", vertex_normals(pos, faces)[:, :2], radial) > 0).all()
    top, bottom = pos[:, 2] > -1e-9, pos[:, 2] < -0.5 + 1e-9
    np.testing.assert_allclose(np.linalg.norm(pos[top, :2], axis=1), 0.15)
    np.testing.assert_allclose(np.linalg.norm(pos[bottom, :2], axis=1), 0.4)


def test_flared_skirt_is_seeded() -> None:
    a, _ = flared_skirt(400, seed=1)
    b, _ = flared_skirt(400, seed=1)
    c, _ = flared_skirt(400, seed=2)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
