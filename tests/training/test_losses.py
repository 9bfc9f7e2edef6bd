"""Each loss on a case with a known answer."""

from __future__ import annotations

import math

import pytest
import torch

from gnngarment.geometry.triangle_frames import rest_triangle_frames as numpy_frames
from gnngarment.geometry.triangle_frames import vertex_masses
from gnngarment.training.losses import (
    blend_shape_loss,
    collision_loss,
    edge_loss,
    gravity_loss,
    normal_loss,
    shear_loss,
    signed_distance,
    stretch_loss,
    vertex_loss,
)
from tests.meshes import grid


def rest_triangle_frames(pos: torch.Tensor, faces: torch.Tensor):
    inverse, area = numpy_frames(pos.numpy(), faces.numpy())
    return torch.from_numpy(inverse), torch.from_numpy(area)


@pytest.fixture
def sheet():
    pos, faces = grid(4, 5, spacing=0.1)
    return torch.tensor(pos, dtype=torch.float64), torch.tensor(faces)


def edges_of(faces: torch.Tensor) -> torch.Tensor:
    pairs = torch.cat([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return torch.unique(torch.sort(pairs, dim=1).values, dim=0).T


def test_supervised_terms_are_zero_on_the_target_and_positive_off_it(sheet) -> None:
    pos, faces = sheet
    edges = edges_of(faces)
    assert vertex_loss(pos, pos) == 0 and edge_loss(pos, pos, edges) == 0
    assert normal_loss(pos, pos, faces).abs() < 1e-12
    moved = pos + torch.tensor([0.0, 0.0, 0.3])  # rigid shift: only the vertex term sees it
    assert math.isclose(vertex_loss(moved, pos).item(), 0.09, rel_tol=1e-6)
    assert edge_loss(moved, pos, edges) < 1e-20 and normal_loss(moved, pos, faces) < 1e-12
    scaled = pos * 2  # every edge doubles
    lengths = (pos[edges[0]] - pos[edges[1]]).norm(dim=-1)
    assert math.isclose(edge_loss(scaled, pos, edges).item(), (lengths**2).mean().item())
    flipped = pos * torch.tensor([1.0, 1.0, -1.0]) + torch.tensor([0, 0, 0.0])
    flipped[:, 0] = -flipped[:, 0]  # mirror x: normals flip to -z
    assert math.isclose(normal_loss(flipped, pos, faces).item(), 2.0, rel_tol=1e-9)


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


def test_gravity_is_weight_times_height_and_pulls_down(sheet) -> None:
    pos, faces = sheet
    mass = torch.from_numpy(vertex_masses(pos.numpy(), faces.numpy(), density=0.2))
    assert math.isclose(mass.sum().item(), 0.2 * 0.4 * 0.3, rel_tol=1e-9)  # 0.4 × 0.3 m sheet
    lifted = (pos + torch.tensor([0.0, 0, 0.1], dtype=pos.dtype)).requires_grad_()
    loss = gravity_loss(lifted, pos, mass, num_garments=2)
    assert math.isclose(loss.item(), 9.81 * 0.024 * 0.1 / 2, rel_tol=1e-6)
    loss.backward()
    assert (lifted.grad[:, 2] > 0).all() and (lifted.grad[:, :2] == 0).all()


def test_blend_shape_penalty_is_zero_for_plain_skinning_and_only_when_asked() -> None:
    from gnngarment.training.config import LossWeights, StageConfig
    from gnngarment.training.objective import stage_weights

    blend = torch.zeros(5, 3)
    assert float(blend_shape_loss(blend)) == 0.0
    blend[0] = torch.tensor([0.03, 0.0, 0.04])                 # one vertex 5 cm off
    assert float(blend_shape_loss(blend)) == pytest.approx(0.05 ** 2 / 5)
    for stage in ("supervised", "physics", "physics_strain"):
        assert "blend_shape" not in stage_weights(stage, LossWeights(), StageConfig())
        assert stage_weights(stage, LossWeights(blend_shape=100.0),
                             StageConfig())["blend_shape"] == 100.0
