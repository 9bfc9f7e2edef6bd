"""The model input of a garment on a body (:func:`garment_pair`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from gnngarment.body.joint_reach import joint_region_distances
from gnngarment.body.weight_transfer import transfer_body_weights
from gnngarment.data.body_inputs import BodyShapeInputs
from gnngarment.inference.animate import garment_pair
from gnngarment.model import GarmentDeformer
from tests.meshes import tube
from tests.model.pairs import tiny_config


def body_shape(config, skinning: bool = True) -> BodyShapeInputs:
    rng = np.random.default_rng(0)
    vertices = rng.normal(scale=0.3, size=(60, 3))
    return BodyShapeInputs(
        joints=rng.normal(scale=0.3, size=(24, 3)).astype(np.float32),
        distances=rng.random((config.body_vertices, 24)).astype(np.float32),
        subset=np.arange(config.body_vertices), rest_vertices=vertices,
        faces=np.zeros((0, 3), np.int64),
        skinning_weights=rng.dirichlet(np.ones(24), size=60) if skinning else None)


def test_body_prior_pairs_carry_the_transferred_body_weights() -> None:
    pos, faces = tube(6, 8)
    model = GarmentDeformer(tiny_config())
    body = body_shape(model.config)
    pair = garment_pair(model, pos, faces, body)
    expected = transfer_body_weights(pos, body.rest_vertices, body.skinning_weights)
    np.testing.assert_allclose(pair.body_weights.numpy(), expected)
    # The weight reach is measured on the chosen body, as the far-joint metric measures.
    np.testing.assert_allclose(
        pair.joint_distances.numpy(),
        joint_region_distances(pos, body.rest_vertices, body.skinning_weights), rtol=1e-6)
    model.encode([pair])  # accepted as it is
    with pytest.raises(ValueError, match="skinning weights"):
        garment_pair(model, pos, faces, body_shape(model.config, skinning=False))


def test_models_without_a_reach_need_no_joint_distances() -> None:
    pos, faces = tube(6, 8)
    model = GarmentDeformer(replace(tiny_config(), weight_reach=None))
    pair = garment_pair(model, pos, faces, body_shape(model.config))
    assert pair.body_weights is not None and pair.joint_distances is None
    model.encode([pair])


def test_models_without_the_prior_need_no_body_weights() -> None:
    pos, faces = tube(6, 8)
    model = GarmentDeformer(replace(tiny_config(), weight_prior="none"))
    pair = garment_pair(model, pos, faces, body_shape(model.config, skinning=False))
    assert pair.body_weights is None and pair.joint_distances is None
    assert torch.isfinite(model.encode([pair]).fused).all()
