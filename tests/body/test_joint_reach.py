"""Which joints may move a garment vertex (the weight head's reach mask): near on the body,
as the far-joint metric measures, and near on the garment."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gnngarment.body.joint_reach import REGION_WEIGHT, joint_region_distances, reachable_joints
from gnngarment.body.weight_transfer import transfer_body_weights
from gnngarment.evaluation.metrics import far_joint_weight


def strip_body(count: int = 101) -> tuple[np.ndarray, np.ndarray]:
    """A "body" of vertices every centimetre along x from 0 to 1 m, with 4 joints:
    joint 0 moves all of it, joint 1 also x < 0.1 m, joint 2 also x > 0.95 m, joint 3
    barely moves one vertex (below the region weight)."""
    x = np.linspace(0.0, 1.0, count)
    vertices = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=1)
    weights = np.zeros((count, 4))
    weights[:, 0] = 1.0
    weights[:10, 0], weights[:10, 1] = 0.5, 0.5
    weights[-5:, 0], weights[-5:, 2] = 0.5, 0.5
    weights[50, 3] = 0.5 * REGION_WEIGHT
    return vertices, weights


def test_distance_is_counted_beyond_the_nearest_body_point() -> None:
    body, weights = strip_body()
    # Garment points 0.3 m above the strip: a hem hanging off the body is not far from
    # the part it hangs from, only from the parts beyond it.
    points = body[::10] + np.array([0.0, 0.3, 0.0])
    distances = joint_region_distances(points, body, weights)
    x = points[:, 0]
    hanging = np.hypot(x[:, None] - body[None, :, 0], 0.3).min(1)
    np.testing.assert_allclose(distances[:, 0], 0.0, atol=1e-12)
    region_1 = np.hypot(np.maximum(x - 0.09, 0.0), 0.3) - hanging
    np.testing.assert_allclose(distances[:, 1], region_1, atol=1e-12)
    assert np.isinf(distances[:, 3]).all()              # moves no vertex by REGION_WEIGHT
    assert (distances >= 0).all()


def test_a_joint_reaches_only_vertices_near_its_body_region() -> None:
    body, weights = strip_body()
    distances = torch.from_numpy(joint_region_distances(body, body, weights))
    transferred = torch.from_numpy(weights / weights.sum(1, keepdims=True))
    everywhere = torch.ones(len(body), 4)           # every joint moves all of the garment
    reach = reachable_joints(torch.from_numpy(body), everywhere, distances, reach=0.205)
    x = body[:, 0]
    assert reach[:, 0].all()
    # The region's last vertex is at 0.09 m (joint 2's first at 0.96 m).
    np.testing.assert_array_equal(reach[:, 1].numpy(), x <= 0.09 + 0.205)
    np.testing.assert_array_equal(reach[:, 2].numpy(), x >= 0.96 - 0.205)
    assert not reach[:, 3].any()
    assert torch.equal(reachable_joints(torch.from_numpy(body), transferred, distances, 0.205)
                       [:, :3], reach[:, :3])


def test_a_joint_reaches_only_vertices_near_its_garment_region() -> None:
    """Near on the body is not enough: a joint that moves no garment vertex within reach
    (the hands for trousers, though the hanging hands are near the hips) gets none."""
    x = torch.linspace(0.0, 1.0, 101)
    pos = torch.stack([x, torch.zeros_like(x), torch.zeros_like(x)], dim=1)
    weights = torch.zeros(len(pos), 4)
    weights[:, 0] = 1.0
    weights[:10, 0], weights[:10, 1] = 0.5, 0.5        # joint 1 moves the garment at x < 0.1
    weights[50, 3] = 0.5 * REGION_WEIGHT                # joint 3 barely moves anything
    near_on_the_body = torch.zeros(len(pos), 4)
    reach = reachable_joints(pos, weights, near_on_the_body, reach=0.205)
    assert reach[:, 0].all()
    np.testing.assert_array_equal(reach[:, 1].numpy(), x.numpy() <= 0.09 + 0.205)
    assert not reach[:, 2].any() and not reach[:, 3].any()


def test_the_reach_forbids_exactly_what_the_far_joint_metric_counts() -> None:
    """Weights masked by the reach have zero far weight at the same radius: every joint
    the metric counts as far is masked, so its bound holds by construction."""
    rng = np.random.default_rng(0)
    body = rng.normal(scale=0.4, size=(400, 3))
    anchors = rng.normal(scale=0.4, size=(24, 3))
    nearest = np.linalg.norm(body[:, None] - anchors[None], axis=-1).argmin(1)
    skinning = np.eye(24)[nearest] * 0.8 + 0.2 / 24
    garment = body[rng.choice(400, 120)] + rng.normal(scale=0.05, size=(120, 3))
    distances = joint_region_distances(garment, body, skinning)
    transferred = torch.from_numpy(transfer_body_weights(garment, body, skinning))
    reachable = reachable_joints(torch.from_numpy(garment), transferred,
                                 torch.from_numpy(distances), 0.2)
    weights = torch.from_numpy(rng.dirichlet(np.ones(24), size=120))   # any prediction
    assert 0 < reachable.sum() < reachable.numel()
    masked = weights * reachable
    masked = (masked / masked.sum(1, keepdim=True)).numpy()
    assert far_joint_weight(masked, garment, body, skinning, radius=0.2)["max"] == 0.0
    unmasked = far_joint_weight(weights.numpy(), garment, body, skinning, radius=0.2)
    expected = (weights.numpy() * (distances > 0.2)).sum(1).max()
    assert not (reachable.numpy() & (distances > 0.2)).any()   # all it counts is masked
    assert unmasked["max"] == pytest.approx(expected)


def test_every_vertex_keeps_its_strongest_joint() -> None:
    weights = torch.full((11, 24), 1 / 24)
    weights[:, 7] += 0.01
    distances = torch.full((11, 24), 1.0)
    reach = reachable_joints(torch.zeros(11, 3), weights, distances, reach=0.05)
    assert reach[:, 7].all() and reach.sum() == 11


def test_reach_is_positive_and_shapes_agree() -> None:
    with pytest.raises(ValueError, match="reach"):
        reachable_joints(torch.zeros(3, 3), torch.full((3, 24), 1 / 24), torch.zeros(3, 24),
                         reach=0.0)
    with pytest.raises(ValueError, match="same shape"):
        reachable_joints(torch.zeros(3, 3), torch.full((3, 24), 1 / 24), torch.zeros(3, 23),
                         reach=0.2)
    with pytest.raises(ValueError, match="body_skinning_weights"):
        joint_region_distances(np.zeros((2, 3)), np.zeros((5, 3)), np.ones((4, 24)))
