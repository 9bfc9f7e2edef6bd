"""Metrics on cases with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.evaluation import metrics
from gnngarment.evaluation.perturbation import descendants, perturb_joint
from tests.meshes import grid


@pytest.fixture
def sheet():
    pos, faces = grid(5, 5, spacing=0.1)
    return np.repeat(pos[None], 3, 0), faces


def edges_of(faces):
    pairs = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return np.unique(np.sort(pairs, 1), axis=0)


def test_identical_prediction_scores_zero(sheet) -> None:
    pos, faces = sheet
    assert np.allclose(metrics.vertex_error(pos, pos), 0)
    assert np.allclose(metrics.normal_error(pos, pos, faces), 0, atol=1e-5)
    assert np.allclose(metrics.hausdorff_distance(pos, pos), 0)
    sted = metrics.spatio_temporal_edge_difference(pos, pos, edges_of(faces), pos[0])
    assert np.allclose(sted, 0)


def test_known_offsets(sheet) -> None:
    pos, faces = sheet
    shifted = pos + np.array([0.0, 0.0, 0.03])
    np.testing.assert_allclose(metrics.vertex_error(shifted, pos), 0.03)
    np.testing.assert_allclose(metrics.hausdorff_distance(shifted, pos), 0.03)
    # A rigid shift keeps every edge: STED is blind to it, as it should be.
    assert np.allclose(metrics.spatio_temporal_edge_difference(shifted, pos, edges_of(faces),
                                                               pos[0]), 0)
    flipped = pos * np.array([1.0, -1.0, 1.0])  # mirrored: normals reverse
    np.testing.assert_allclose(metrics.normal_error(flipped, pos, faces), 180, atol=1e-3)
    stretched = pos * np.array([1.1, 1.0, 1.0])
    sted = metrics.spatio_temporal_edge_difference(stretched, pos, edges_of(faces), pos[0])
    assert (sted[0] > 0.01) and np.allclose(sted, sted[0])  # no temporal change


def test_collision_rate_counts_vertices_below_the_surface(sheet) -> None:
    pos, _ = sheet
    floor = np.stack(np.meshgrid(np.linspace(-1, 1, 20), np.linspace(-1, 1, 20)), -1)
    points = np.concatenate([floor.reshape(-1, 2), np.zeros((400, 1))], 1)
    body = np.repeat(points[None], 3, 0)
    normals = np.tile([0.0, 0.0, 1.0], (3, 400, 1))
    lowered = pos.copy()
    lowered[:, :5, 2] = -0.01  # 5 of 25 vertices below
    np.testing.assert_allclose(metrics.collision_rate(lowered, body, normals), 20.0)


def test_perturbation_moves_only_the_subtree() -> None:
    rest_joints = np.random.default_rng(0).normal(size=(24, 3))
    transforms = np.tile(np.eye(4, dtype=np.float32), (4, 24, 1, 1))
    features = np.zeros((4, 75), np.float32)
    assert descendants(20) == [20, 22]  # L_wrist -> L_hand
    new_features, new_transforms = perturb_joint(features, transforms, rest_joints, "L_wrist",
                                                 np.array([0.5, 0, 0]))
    np.testing.assert_allclose(new_features[:, 60:63], [[0.5, 0, 0]] * 4, atol=1e-6)
    changed = np.flatnonzero(np.abs(new_transforms - transforms).sum((0, 2, 3)) > 1e-6)
    assert changed.tolist() == [20, 22]
    # The wrist's own rest position is a fixed point of its perturbed transform.
    point = np.append(rest_joints[20], 1.0)
    np.testing.assert_allclose(new_transforms[0, 20] @ point, point, atol=1e-5)
    _, same_transforms = perturb_joint(features, transforms, rest_joints, "L_wrist",
                                                   np.zeros(3))
    np.testing.assert_allclose(same_transforms, transforms, atol=1e-6)


def test_far_joint_weight_counts_weight_on_distant_body_regions() -> None:
    # Body: joint 0 moves a cluster at x = 0 (with joint 3, which dominates no vertex but
    # moves them by 0.3, as Anny's pelvis does), joint 1 one at x = 1; every vertex
    # carries a trace of joint 2, below the region threshold.
    body = np.array([[0.0, 0, 0], [0.0, 0.1, 0], [1.0, 0, 0], [1.0, 0.1, 0]])
    body_weights = np.zeros((4, 24))
    body_weights[:2, 0], body_weights[:2, 3] = 0.65, 0.3
    body_weights[2:, 1], body_weights[:, 2] = 0.95, 0.05
    rest = np.array([[0.05, 0, 0], [0.95, 0, 0]])   # garment vertices near each cluster
    weights = np.zeros((2, 2, 24))
    weights[0, 0, [3, 1]] = 0.7, 0.3                 # joint 3 is near; 0.3 on far joint 1
    weights[0, 1, 1] = 1.0                           # all on its own region
    weights[1, 0, 0] = 1.0
    weights[1, 1, [1, 2]] = 0.4, 0.6                 # 0.6 on joint 2: no region, far
    result = metrics.far_joint_weight(weights, rest, body, body_weights, radius=0.2)
    assert result["max"] == pytest.approx(0.6)
    assert result["mean"] == pytest.approx((0.3 + 0 + 0 + 0.6) / 4)
    # A radius wider than the body: only the region-less joint 2 is still far.
    wide = metrics.far_joint_weight(weights[0], rest, body, body_weights, radius=2.0)
    assert wide == {"max": 0.0, "mean": 0.0}
    with pytest.raises(ValueError, match="weights must be"):
        metrics.far_joint_weight(weights[:, :1], rest, body, body_weights)
