"""`delaunay_flips`: edge flips that keep the mesh valid."""

from __future__ import annotations

import numpy as np

from data_prep.garments.flips import delaunay_flips
from gnngarment.geometry import check_mesh


def test_delaunay_flips_keep_a_valid_mesh(garments: dict) -> None:
    garment = garments["dress"]
    rng = np.random.default_rng(0)
    noisy = garment.pos + rng.normal(0, 0.004, garment.pos.shape)
    faces = delaunay_flips(noisy, garment.faces)
    report = check_mesh(noisy, faces)
    assert report.ok and not report.findings
    assert len(faces) == len(garment.faces)
