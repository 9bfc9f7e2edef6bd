"""A small flat sheet of cloth for the criteria tests."""

from __future__ import annotations

import torch

from gnngarment.geometry.triangle_frames import rest_triangle_frames as numpy_frames
from tests.meshes import grid


def sheet() -> tuple[torch.Tensor, torch.Tensor]:
    """``(20, 3)`` float64 vertices of a 0.4 × 0.3 m grid in the plane z = 0, its faces."""
    pos, faces = grid(4, 5, spacing=0.1)
    return torch.tensor(pos, dtype=torch.float64), torch.tensor(faces)


def edges_of(faces: torch.Tensor) -> torch.Tensor:
    pairs = torch.cat([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return torch.unique(torch.sort(pairs, dim=1).values, dim=0).T


def rest_triangle_frames(pos: torch.Tensor, faces: torch.Tensor):
    inverse, area = numpy_frames(pos.numpy(), faces.numpy())
    return torch.from_numpy(inverse), torch.from_numpy(area)
