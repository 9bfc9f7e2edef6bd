"""The data contract between cache and model (:class:`GarmentBodyPair`).

The pair itself is a plain container; what it promises is checked where pairs are made
(the cache reader, inference's ``garment_pair``) and where they are used
(:func:`check_pair_fits`, run by ``GarmentDeformer.prepare`` on every pair).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import torch

from gnngarment.data import PreparedDataset
from gnngarment.data.body_inputs import BodyShapeInputs
from gnngarment.data.cache import read_body, read_garment
from gnngarment.data.pair import GarmentBodyPair
from gnngarment.data.vertex_features import VERTEX_FEATURE_CHANNELS, garment_vertex_features
from gnngarment.inference.animate import garment_pair
from gnngarment.model import GarmentDeformer
from gnngarment.model.deformer import check_pair_fits
from tests.meshes import tube
from tests.model.pairs import make_pair, tiny_config
from tests.synthetic_cache import build_synthetic_cache

LANDMARKS, BODY_VERTICES, LEVELS = 16, 32, 2


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_synthetic_cache(tmp_path_factory.mktemp("cache"), frames=2,
                                 landmarks=LANDMARKS, body_vertices=BODY_VERTICES,
                                 levels=LEVELS)


def config(**overrides):
    return tiny_config(landmarks=LANDMARKS, body_vertices=BODY_VERTICES, levels=LEVELS,
                       **overrides)


def test_body_weights_default_to_unknown() -> None:
    pair = make_pair(*tube(4, 6), config())
    bare = GarmentBodyPair(rest_pos=pair.rest_pos, features=pair.features,
                           hierarchy=pair.hierarchy, descriptor=pair.descriptor,
                           body_distances=pair.body_distances)
    assert bare.body_weights is None
    check_pair_fits(bare, config(weight_prior="none"))  # a model without the prior takes it
    with pytest.raises(ValueError, match="body_weights is missing"):
        check_pair_fits(bare, config())


def test_from_arrays_gives_float32_tensors_of_the_same_values() -> None:
    pair = make_pair(*tube(4, 6), config())
    built = GarmentBodyPair.from_arrays(
        pair.rest_pos.double().numpy(), pair.features.numpy(), pair.hierarchy,
        pair.descriptor.double().numpy(), pair.body_distances.numpy(),
        pair.body_weights.double().numpy(), pair.joint_distances.double().numpy())
    for name in ("rest_pos", "features", "descriptor", "body_distances", "body_weights",
                 "joint_distances"):
        value = getattr(built, name)
        assert value.dtype == torch.float32, name
        assert torch.equal(value, getattr(pair, name)), name
    assert built.hierarchy is pair.hierarchy
    assert GarmentBodyPair.from_arrays(
        pair.rest_pos.numpy(), pair.features.numpy(), pair.hierarchy,
        pair.descriptor.numpy(), pair.body_distances.numpy()).body_weights is None


def test_cached_pairs_have_the_documented_shapes_and_contents(cache: Path) -> None:
    dataset = PreparedDataset(cache, "train", window=2)
    for name in dataset.sequence_names:
        pair = dataset.garment_of(name).pair
        info = dataset.manifest["sequences"][name]
        record, body = read_garment(cache, info["garment"]), read_body(cache, info["body"])
        n = len(record.rest_pos)
        assert pair.rest_pos.shape == (n, 3) and pair.rest_pos.dtype == torch.float32
        assert pair.features.shape == (n, VERTEX_FEATURE_CHANNELS)
        assert pair.features.dtype == torch.float32
        np.testing.assert_array_equal(
            pair.features.numpy(),
            garment_vertex_features(record.rest_pos, record.faces, body.joints))
        assert pair.hierarchy.num_vertices == n and pair.hierarchy.depth == LEVELS
        assert pair.descriptor.shape == (LANDMARKS,)
        np.testing.assert_array_equal(pair.body_distances.numpy(), body.distances)
        assert pair.body_distances.shape == (BODY_VERTICES, 24)
        assert pair.body_weights.shape == (n, 24)
        np.testing.assert_allclose(pair.body_weights.sum(1).numpy(), 1.0, rtol=1e-6)
        np.testing.assert_array_equal(pair.joint_distances.numpy(), record.joint_distances)
        check_pair_fits(pair, config())


def test_inference_builds_the_pair_the_cache_holds(cache: Path) -> None:
    # Same garment on the same body: the model must see the same numbers at inference
    # as in training (the cache's body weights are synthetic, so the prior is off here).
    model = GarmentDeformer(config(weight_prior="none"))
    dataset = PreparedDataset(cache, "train", window=2)
    name = dataset.sequence_names[0]
    info = dataset.manifest["sequences"][name]
    record, body = read_garment(cache, info["garment"]), read_body(cache, info["body"])
    shape = BodyShapeInputs(joints=body.joints, distances=body.distances, subset=body.subset,
                            rest_vertices=np.zeros((0, 3)), faces=np.zeros((0, 3), np.int64))
    built = garment_pair(model, record.rest_pos, record.faces, shape)
    cached = dataset.garment_of(name).pair
    for field in ("rest_pos", "features", "body_distances"):
        assert torch.equal(getattr(built, field), getattr(cached, field)), field
    np.testing.assert_allclose(built.descriptor.numpy(), cached.descriptor.numpy(),
                               rtol=1e-5, atol=1e-7)
    np.testing.assert_array_equal(built.hierarchy.edge_index, cached.hierarchy.edge_index)
    assert built.hierarchy.vertex_counts() == cached.hierarchy.vertex_counts()


@pytest.mark.parametrize(("change", "message"), [
    (lambda p: dict(rest_pos=p.rest_pos[:, :2]), r"rest_pos has shape \((\d+), 2\), expected"),
    (lambda p: dict(features=p.features[:-1]), r"features has shape \(\d+, 30\), expected"),
    (lambda p: dict(features=p.features[:, :29]), r"features has shape \(\d+, 29\)"),
    (lambda p: dict(descriptor=p.descriptor[:8]),
     r"descriptor has shape \(8,\), expected \(16,\) \(the model's landmarks is 16\)"),
    (lambda p: dict(body_distances=p.body_distances[:20]),
     r"body_distances has shape \(20, 24\), expected \(32, 24\) "
     r"\(the model's body_vertices is 32\)"),
    (lambda p: dict(body_distances=p.body_distances.clone().fill_(float("inf"))),
     "body_distances contains NaN or inf"),
    (lambda p: dict(body_weights=p.body_weights[:, :23]),
     r"body_weights has shape \(\d+, 23\), expected \(\d+, 24\)"),
    (lambda p: dict(joint_distances=None), r"joint_distances is missing; weight_reach 0.2"),
    (lambda p: dict(joint_distances=p.joint_distances[:-1]),
     r"joint_distances has shape \(\d+, 24\), expected"),
    (lambda p: dict(joint_distances=p.joint_distances.clone().fill_(float("nan"))),
     r"joint_distances contains NaN$"),
    (lambda p: dict(rest_pos=p.rest_pos[:-1], features=p.features[:-1],
                    body_weights=p.body_weights[:-1], joint_distances=p.joint_distances[:-1]),
     r"hierarchy has (\d+) vertices, garment has"),
])
def test_a_pair_of_mismatched_arrays_is_rejected_naming_the_array(change, message: str
                                                                  ) -> None:
    pair = make_pair(*tube(4, 6), config(), levels=LEVELS)
    check_pair_fits(pair, config())
    with pytest.raises(ValueError, match=message):
        check_pair_fits(replace(pair, **change(pair)), config())
