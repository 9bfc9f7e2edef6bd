"""The collision term and its signed distance."""

from __future__ import annotations

import math

import torch

from gnngarment.training.criteria.collision import collision_loss, signed_distance


def test_collision_is_zero_outside_and_pushes_out_when_inside() -> None:
    # Body: points on the plane z = 0 with normals +z (a floor seen as a body surface).
    xs, ys = torch.meshgrid(torch.linspace(-1, 1, 21), torch.linspace(-1, 1, 21), indexing="ij")
    body = torch.stack([xs.ravel(), ys.ravel(), torch.zeros(441)], -1)
    normals = torch.tensor([[0.0, 0.0, 1.0]]).repeat(441, 1)
    body_item = torch.zeros(441, dtype=torch.long)
    above = torch.tensor([[0.0, 0.0, 0.05], [0.3, 0.1, 0.2]])
    item = torch.zeros(2, dtype=torch.long)
    assert collision_loss(above, body, normals, item, body_item) == 0
    inside = torch.tensor([[0.0, 0.0, -0.02], [0.3, 0.1, 0.2]], requires_grad=True)
    torch.testing.assert_close(signed_distance(inside, body, normals, item, body_item),
                               torch.tensor([-0.02, 0.2]))
    loss = collision_loss(inside, body, normals, item, body_item, margin=0.004)
    assert math.isclose(loss.item(), (0.02 + 0.004) / 2, rel_tol=1e-5)
    loss.backward()
    assert inside.grad[0, 2] < 0 and inside.grad[1].abs().sum() == 0  # descent lifts it


def test_collision_uses_each_items_own_body() -> None:
    body = torch.tensor([[0.0, 0, 0], [0.0, 0, 10]])
    normals = torch.tensor([[0.0, 0, 1], [0.0, 0, -1]])
    body_item = torch.tensor([0, 1])
    pos = torch.tensor([[0.0, 0, 9.0], [0.0, 0, 9.0]])
    distance = signed_distance(pos, body, normals, torch.tensor([0, 1]), body_item)
    torch.testing.assert_close(distance, torch.tensor([9.0, 1.0]))
