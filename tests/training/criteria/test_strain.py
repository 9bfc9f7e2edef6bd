"""Stretch and shear on cases with a known answer."""

from __future__ import annotations

import math

import torch

from gnngarment.training.criteria.strain import shear_loss, stretch_loss
from tests.training.criteria.sheets import rest_triangle_frames


def test_stretch_and_shear_zero_at_rest_and_under_rigid_motion(sheet) -> None:
    pos, faces = sheet
    inverse, area = rest_triangle_frames(pos, faces)
    rotation = torch.tensor([[0.0, -1, 0], [0, 0, 1], [-1, 0, 0]], dtype=pos.dtype)
    for moved in (pos, pos @ rotation.T + 0.5):
        assert stretch_loss(moved, faces, inverse, area) < 1e-20
        assert shear_loss(moved, faces, inverse, area) < 1e-20


def test_stretch_has_the_analytic_value_and_pulls_back(sheet) -> None:
    pos, faces = sheet
    inverse, area = rest_triangle_frames(pos, faces)
    stretched = (pos * torch.tensor([1.2, 1.0, 1.0])).requires_grad_()
    loss = stretch_loss(stretched, faces, inverse, area)
    # Uniform 20% stretch along x: E_xx = (1.2² - 1)/2 = 0.22 in every triangle. The rest
    # frames are rotated per triangle, so compare the invariant E_uu² + E_vv² + 2E_uv².
    total = loss + 2 * shear_loss(stretched, faces, inverse, area)
    assert math.isclose(total.item(), 0.22**2, rel_tol=1e-6)
    loss.backward()
    # The gradient on the far column points along +x: descent shrinks it back.
    far = pos[:, 0] == pos[:, 0].max()
    assert (stretched.grad[far, 0] > 0).all()


def test_shear_is_positive_for_sheared_cloth(sheet) -> None:
    pos, faces = sheet
    inverse, area = rest_triangle_frames(pos, faces)
    sheared = pos.clone()
    sheared[:, 0] += 0.3 * pos[:, 1]
    assert shear_loss(sheared, faces, inverse, area) > 1e-3
