"""The gravity term."""

from __future__ import annotations

import math

import torch

from gnngarment.geometry.triangle_frames import vertex_masses
from gnngarment.training.criteria.gravity import gravity_loss


def test_gravity_is_weight_times_height_and_pulls_down(sheet) -> None:
    pos, faces = sheet
    mass = torch.from_numpy(vertex_masses(pos.numpy(), faces.numpy(), density=0.2))
    assert math.isclose(mass.sum().item(), 0.2 * 0.4 * 0.3, rel_tol=1e-9)  # 0.4 × 0.3 m sheet
    lifted = (pos + torch.tensor([0.0, 0, 0.1], dtype=pos.dtype)).requires_grad_()
    loss = gravity_loss(lifted, pos, mass, num_garments=2)
    assert math.isclose(loss.item(), 9.81 * 0.024 * 0.1 / 2, rel_tol=1e-6)
    loss.backward()
    assert (lifted.grad[:, 2] > 0).all() and (lifted.grad[:, :2] == 0).all()
