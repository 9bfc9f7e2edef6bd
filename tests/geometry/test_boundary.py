"""Boundary loops, and the loop a rest drape holds a garment by."""

from __future__ import annotations

import numpy as np

from gnngarment.geometry.boundary import boundary_loops, support_band
from tests.meshes import random_disk, tube


def _cylinder_body(radius: float = 0.12) -> np.ndarray:
    angles = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    heights = np.linspace(-0.2, 0.8, 41)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    return np.concatenate([np.column_stack([ring, np.full(64, z)]) for z in heights])


def test_a_tube_has_two_loops_in_order() -> None:
    pos, faces = tube(12, 16)
    loops = boundary_loops(faces)
    assert len(loops) == 2 and sorted(len(loop) for loop in loops) == [16, 16]
    for loop in loops:  # consecutive loop vertices share a boundary edge
        assert np.allclose(np.ptp(pos[loop, 2]), 0.0)


def test_the_top_ring_around_the_body_holds_the_garment() -> None:
    pos, faces = tube(12, 16)  # a skirt-like tube around the vertical axis
    band = support_band(pos, faces, _cylinder_body())
    top = np.flatnonzero(np.isclose(pos[:, 2], pos[:, 2].max()))
    assert sorted(band.tolist()) == sorted(top.tolist())


def test_no_band_when_the_top_loop_does_not_go_around_the_body() -> None:
    pos, faces = random_disk(150, 3)
    beside = pos + np.array([0.4, 0.0, 0.0])  # a flat patch next to the body
    assert len(support_band(beside, faces, _cylinder_body())) == 0
    # half a tube (an open sleeve cut lengthwise) leaves a gap of 180 degrees
    pos, faces = tube(12, 16)
    keep = np.all(pos[faces][:, :, 1] >= -1e-9, axis=1)
    assert len(support_band(pos, faces[keep], _cylinder_body())) == 0
