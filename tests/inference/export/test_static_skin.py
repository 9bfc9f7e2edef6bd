"""Static top-K skin and the rest-frame residuals that make it exact."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.inference.export.static_skin import (
    rest_frame_residuals,
    skin_static,
    static_skin,
)
from tests.inference.animations import joint_transforms, per_frame_weights, rest_garment


def test_top_k_of_the_mean_renormalised_and_sorted() -> None:
    weights = np.zeros((2, 1, 24))
    weights[0, 0, [3, 5, 7, 9, 11]] = [0.5, 0.2, 0.1, 0.1, 0.1]
    weights[1, 0, [3, 5, 7, 9, 11]] = [0.3, 0.4, 0.1, 0.1, 0.1]
    skin = static_skin(weights, max_influences=2)
    np.testing.assert_array_equal(skin.joints, [[3, 5]])
    np.testing.assert_allclose(skin.weights, [[0.4 / 0.7, 0.3 / 0.7]], rtol=1e-6)
    assert static_skin(weights, 1, reference=1).joints.tolist() == [[5]]


def test_rows_sum_to_one_in_float32_and_zero_weights_use_joint_zero() -> None:
    weights = per_frame_weights(rest_garment()[0], 4)
    skin = static_skin(weights, max_influences=8)
    assert skin.weights.dtype == np.float32
    np.testing.assert_allclose(skin.weights.astype(np.float64).sum(axis=1), 1.0, atol=1e-7)
    sparse = np.zeros((1, 2, 24))
    sparse[0, :, 4] = 1.0
    one = static_skin(sparse, max_influences=4)
    np.testing.assert_array_equal(one.joints, [[4, 0, 0, 0]] * 2)
    np.testing.assert_array_equal(one.weights, [[1, 0, 0, 0]] * 2)


def test_residuals_reproduce_the_target_exactly() -> None:
    pos, _ = rest_garment()
    transforms = joint_transforms(4).astype(np.float64)
    weights = per_frame_weights(pos, 4).astype(np.float64)
    dense = np.einsum("tnj,tjab->tnab", weights, transforms[..., :3, :])
    posed = np.einsum("tnab,nb->tna", dense[..., :3], pos) + dense[..., 3]
    skin = static_skin(weights, 4)
    residuals = rest_frame_residuals(pos, posed, skin, transforms)
    assert residuals.ill_conditioned == 0
    np.testing.assert_allclose(skin_static(pos, residuals.offsets, skin, transforms), posed,
                               atol=1e-9)
    # With all 24 influences and weights constant in time, no residual is needed.
    still = np.broadcast_to(weights[:1], weights.shape)
    dense = np.einsum("tnj,tjab->tnab", still, transforms[..., :3, :])
    posed = np.einsum("tnab,nb->tna", dense[..., :3], pos) + dense[..., 3]
    exact = rest_frame_residuals(pos, posed, static_skin(still, 24), transforms)
    assert np.abs(exact.offsets).max() < 1e-6


def test_singular_blends_fall_back_to_least_squares() -> None:
    # Half/half between the identity and a half turn: the blended matrix is singular.
    transforms = np.tile(np.eye(4), (1, 24, 1, 1))
    transforms[0, 1, :3, :3] = np.diag([-1.0, -1.0, 1.0])
    weights = np.zeros((1, 1, 24))
    weights[0, 0, :2] = 0.5
    residuals = rest_frame_residuals(np.ones((1, 3)), np.ones((1, 1, 3)),
                                     static_skin(weights, 2), transforms)
    assert residuals.ill_conditioned == 1
    assert np.isfinite(residuals.offsets).all()


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"max_influences": 0}, "max_influences"),
    ({"reference": 5}, "reference"),
    ({"reference": "median"}, "reference"),
])
def test_bad_options(kwargs, message) -> None:
    with pytest.raises(ValueError, match=message):
        static_skin(np.full((2, 3, 24), 1 / 24), **kwargs)


def test_bad_weights() -> None:
    with pytest.raises(ValueError, match="non-negative"):
        static_skin(-np.ones((1, 2, 24)))
    with pytest.raises(ValueError, match="all-zero"):
        static_skin(np.zeros((1, 2, 24)))
