"""The supervised terms (vertex, edge, normal) on a case with a known answer."""

from __future__ import annotations

import math

import torch

from gnngarment.training.criteria.edge import edge_loss
from gnngarment.training.criteria.normal import normal_loss
from gnngarment.training.criteria.vertex import vertex_loss
from tests.training.criteria.sheets import edges_of


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
