"""`silhouette`, `trace`, `lift_on_grid` and `surface_area` on a skirt around the
synthetic body: a tube seen from the front is one region bounded by two seams, the
waist and the hem."""

from __future__ import annotations

import numpy as np
import pytest

from data_prep.garments import BodyFrame, SkirtStyle
from data_prep.garments.panel_boundary import trace
from data_prep.garments.silhouette import lift_on_grid, silhouette, surface_area
from data_prep.garments.skirt import skirt_outline


@pytest.fixture(scope="module")
def skirt(body: BodyFrame):
    design = skirt_outline(body, SkirtStyle()).design
    return design, silhouette(design, grid=0.015)


def test_a_skirt_panel_is_two_seams_and_two_openings(skirt) -> None:
    design, sil = skirt
    for side in (-1, 1):
        boundary = trace(design, sil, side)
        assert sorted(boundary.labels) == [0, 0, 1, 2]  # seams, waist (cut 0), hem (cut 1)
        for run, following in zip(boundary.runs, boundary.runs[1:] + boundary.runs[:1],
                                  strict=True):
            np.testing.assert_allclose(run[-1], following[0])
        loop = np.concatenate([run[:-1] for run in boundary.runs])
        area = 0.5 * np.sum(loop[:, 0] * np.roll(loop[:, 1], -1)
                            - np.roll(loop[:, 0], -1) * loop[:, 1])
        assert area > 0  # counter-clockwise in (x, z)


def test_lifted_points_lie_on_the_surface(skirt) -> None:
    design, sil = skirt
    rows, cols = np.nonzero(sil.region[-1] < -0.01)
    pick = np.random.default_rng(0).choice(len(rows), 50, replace=False)
    xz = np.stack([sil.x[cols[pick]], sil.z[rows[pick]]], axis=1)
    for side in (-1, 1):
        lifted = lift_on_grid(sil, xz, np.full(len(xz), side))
        assert np.abs(design.field(lifted)).max() < 0.01  # metres


def test_surface_area_exceeds_the_flat_pattern(skirt) -> None:
    _, sil = skirt
    total, flat = surface_area(sil)
    assert set(flat) == {-1, 1}
    assert flat[-1] + flat[1] < total < 4 * (flat[-1] + flat[1])
