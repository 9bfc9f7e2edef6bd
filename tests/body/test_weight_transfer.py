"""Body weights carried to a garment: the body-skinning baseline and the weight prior."""

from __future__ import annotations

import numpy as np

from gnngarment.body.weight_transfer import transfer_body_weights


def test_rows_sum_to_one_and_a_vertex_on_the_body_takes_its_weights() -> None:
    rng = np.random.default_rng(0)
    body = rng.normal(size=(200, 3))
    weights = rng.dirichlet(np.ones(24), size=200)
    garment = np.concatenate([body[:5], rng.normal(size=(50, 3))])
    carried = transfer_body_weights(garment, body, weights)
    assert carried.shape == (55, 24) and carried.dtype == np.float32
    np.testing.assert_allclose(carried.sum(axis=1), 1.0, atol=1e-6)
    # On a body vertex the inverse distance (floored at 1 µm) leaves only that vertex.
    np.testing.assert_allclose(carried[:5], weights[:5], atol=1e-4)
    # Elsewhere: a mix of its 4 nearest body vertices, so within their range.
    assert (carried >= 0).all() and (carried <= 1).all()
