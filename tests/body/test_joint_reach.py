"""Which joints may move a garment vertex (the weight head's reach mask)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gnngarment.body.joint_reach import REGION_WEIGHT, reachable_joints


def strip(count: int = 101) -> torch.Tensor:
    """Vertices every centimetre along x, from 0 to 1 m."""
    x = torch.linspace(0.0, 1.0, count)
    return torch.stack([x, torch.zeros_like(x), torch.zeros_like(x)], dim=1)


def test_a_joint_reaches_only_vertices_near_its_region() -> None:
    pos = strip()
    weights = torch.zeros(len(pos), 4)
    weights[:, 0] = 1.0
    weights[:10, 0], weights[:10, 1] = 0.5, 0.5        # joint 1 moves x < 0.1 m
    weights[-5:, 0], weights[-5:, 2] = 0.5, 0.5        # joint 2 moves x > 0.95 m
    weights[50, 3] = 0.5 * REGION_WEIGHT                # joint 3 barely moves anything
    reach = reachable_joints(pos, weights, reach=0.205)   # off the 1 cm grid
    x = pos[:, 0].numpy()
    assert reach[:, 0].all()
    # A 1 cm grid: the region's last vertex is at 0.09 m (first at 0.96 m).
    np.testing.assert_array_equal(reach[:, 1].numpy(), x <= 0.09 + 0.205)
    np.testing.assert_array_equal(reach[:, 2].numpy(), x >= 0.96 - 0.205)
    assert not reach[:, 3].any()


def test_every_vertex_keeps_its_strongest_joint() -> None:
    pos = strip(11)
    weights = torch.full((11, 24), 1 / 24)             # nothing reaches REGION_WEIGHT
    weights[:, 7] += 0.01
    weights /= weights.sum(1, keepdim=True)
    reach = reachable_joints(pos, weights, reach=0.05)
    assert reach[:, 7].all() and reach.sum() == 11


def test_reach_is_positive() -> None:
    with pytest.raises(ValueError, match="reach"):
        reachable_joints(strip(3), torch.full((3, 24), 1 / 24), reach=0.0)
