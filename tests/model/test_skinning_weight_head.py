"""The skinning-weight head (Eq. 6) and its body-skinning prior."""

from __future__ import annotations

from dataclasses import asdict, replace

import pytest
import torch

from gnngarment.body.skinning import skin
from gnngarment.model import GarmentDeformer
from gnngarment.model.checkpoint import load_model, model_payload, save_checkpoint
from gnngarment.model.skinning_weight_head import (
    BODY_WEIGHT_FLOOR,
    SkinningWeightHead,
    body_prior_logits,
)
from tests.meshes import random_disk, tube
from tests.model.pairs import frame_inputs, make_pair, tiny_config


@pytest.fixture(scope="module")
def garment():
    return random_disk(120, 7)


def build(seed: int = 0, **overrides) -> GarmentDeformer:
    torch.manual_seed(seed)
    return GarmentDeformer(tiny_config(**overrides)).eval()


def floored(weights: torch.Tensor) -> torch.Tensor:
    weights = weights.clamp_min(BODY_WEIGHT_FLOOR)
    return weights / weights.sum(-1, keepdim=True)


def test_untrained_body_prior_is_body_skinning(garment) -> None:
    model = build(weight_reach=None)
    pair = make_pair(*garment, model.config)
    pair.body_weights[:5] = torch.eye(24)[:5]  # exact zeros meet the floor
    motion, velocity, transforms = frame_inputs(model.config, 1, 3, seed=2)
    out = model(model.encode([pair]), motion, velocity, transforms)

    expected = floored(pair.body_weights).repeat(3, 1)
    torch.testing.assert_close(out.weights, expected, atol=1e-5, rtol=0)
    # The floor moves at most 23 · 1e-6 of a one-hot row onto the other joints.
    torch.testing.assert_close(out.weights[:5], torch.eye(24)[:5], atol=24 * BODY_WEIGHT_FLOOR,
                               rtol=0)
    lbs = skin(pair.rest_pos.repeat(3, 1), out.blend_shapes, expected,
               transforms.flatten(0, 1), batch=out.item)
    torch.testing.assert_close(out.posed, lbs, atol=1e-5, rtol=0)


def test_untrained_head_with_a_reach_is_body_skinning_on_the_reachable_joints(garment
                                                                              ) -> None:
    from gnngarment.body.joint_reach import reachable_joints

    model = build()
    assert model.config.weight_reach == 0.2
    pair = make_pair(*garment, model.config)
    out = model(model.encode([pair]), *frame_inputs(model.config, 1, 2))
    reachable = reachable_joints(pair.rest_pos, pair.body_weights, pair.joint_distances, 0.2)
    kept = floored(pair.body_weights) * reachable
    expected = (kept / kept.sum(-1, keepdim=True)).repeat(2, 1)
    torch.testing.assert_close(out.weights, expected, atol=1e-6, rtol=0)


def test_reach_mask_is_computed_once_per_pair(garment, monkeypatch) -> None:
    # encode runs on every training step; the mask is a constant of the pair's tensors.
    from gnngarment.model import skinning_weight_head

    calls = []
    original = skinning_weight_head.reachable_joints
    monkeypatch.setattr(skinning_weight_head, "reachable_joints",
                        lambda *args: calls.append(1) or original(*args))
    model = build()
    pair = make_pair(*garment, model.config)
    first = body_prior_logits(pair.body_weights, pair.rest_pos, pair.joint_distances, 0.2)
    again = body_prior_logits(pair.body_weights, pair.rest_pos, pair.joint_distances, 0.2)
    assert len(calls) == 1 and torch.equal(first, again)
    # Other tensors (here: the garment scaled 3×, so its garment regions are farther
    # apart) or another reach are computed afresh, never served a stale mask.
    scaled = pair.rest_pos * 3.0
    shifted = body_prior_logits(pair.body_weights, scaled, pair.joint_distances, 0.2)
    assert len(calls) == 2
    expected = original(scaled, pair.body_weights, pair.joint_distances, 0.2)
    assert torch.equal(torch.isfinite(shifted), expected)
    assert not torch.equal(torch.isfinite(shifted), torch.isfinite(first))
    body_prior_logits(pair.body_weights, pair.rest_pos, pair.joint_distances, 0.1)
    assert len(calls) == 3


def test_body_prior_is_per_pair_in_a_batch(garment) -> None:
    model = build(weight_reach=None)
    pairs = [make_pair(*garment, model.config, seed=1), make_pair(*tube(6, 8), model.config,
                                                                seed=2)]
    out = model(model.encode(pairs), *frame_inputs(model.config, 2, 2))
    for p, part in enumerate(out.split("weights", [120, 48], 2)):
        torch.testing.assert_close(part, floored(pairs[p].body_weights).expand(2, -1, -1),
                                   atol=1e-5, rtol=0)


def test_no_prior_is_the_plain_softmax_head(garment) -> None:
    """``none`` is the paper's head: no parameter, ``softmax(X^fuse · E^t1)``, and the
    pair's body weights are ignored."""
    model = build(weight_prior="none")
    assert not any("weight_head" in name for name, _ in model.named_parameters())
    pair = make_pair(*garment, model.config)
    motion, velocity, transforms = frame_inputs(model.config, 1, 2)
    context = model.encode([pair])
    assert context.prior_logits is None
    out = model(context, motion, velocity, transforms)
    pose_code, _ = model.pose_encoder(motion.flatten(0, 1))
    expected = torch.softmax(torch.einsum("nsf,bf->bns", context.fused, pose_code), -1)
    torch.testing.assert_close(out.weights, expected.flatten(0, 1))
    without = model(model.encode([replace(pair, body_weights=None)]), motion, velocity,
                    transforms)
    assert torch.equal(out.posed, without.posed)


def test_gradients_reach_the_gate_and_then_everything(garment) -> None:
    model = build()
    model.train()
    pair = make_pair(*garment, model.config)
    inputs = frame_inputs(model.config, 1, 2)
    target = torch.randn(2 * 120, 3)

    out = model(model.encode([pair]), *inputs)
    ((out.posed - target) ** 2).mean().backward()
    gate = model.weight_head.gate
    assert gate is not None and gate.grad is not None and gate.grad.abs() > 0
    for name, parameter in model.named_parameters():  # the fused features train from step 1
        if name.startswith(("garment_encoder", "style_encoder", "body_encoder")):
            assert parameter.grad is not None and parameter.grad.abs().sum() > 0, name
    # At g = 0 the pose code only reaches W through the gate; once the gate moves, every
    # supervised parameter, E^t1 included, receives a gradient.
    assert all(p.grad is None or p.grad.abs().sum() == 0
               for p in model.pose_encoder.parameters())
    optimiser = torch.optim.Adamax(model.parameters(), lr=1e-2)
    optimiser.step()
    optimiser.zero_grad(set_to_none=True)
    out = model(model.encode([pair]), *inputs)
    ((out.posed - target) ** 2).mean().backward()
    assert gate.item() != 0
    for name, parameter in model.named_parameters():
        if not name.startswith("physics_processor"):
            assert parameter.grad is not None and parameter.grad.abs().sum() > 0, name


def test_head_alone_matches_its_formula() -> None:
    generator = torch.Generator().manual_seed(0)
    fused, code = torch.randn(5, 24, 4, generator=generator), torch.randn(3, 4, generator=generator)
    prior = torch.softmax(torch.randn(5, 24, generator=generator), -1)
    head = SkinningWeightHead(body_prior=True)
    with torch.no_grad():
        head.gate.fill_(0.5)
    expected = torch.softmax(torch.log(prior) + 0.5 * torch.einsum("nsf,bf->bns", fused, code),
                             -1)
    torch.testing.assert_close(head(fused, code, body_prior_logits(prior)), expected)
    with pytest.raises(ValueError, match="prior_logits"):
        head(fused, code)


@pytest.mark.parametrize("body_weights,message", [
    (None, "body_weights is missing"),
    (torch.full((7, 24), 1 / 24), "body_weights has shape"),
    (torch.full((120, 24), float("nan")), "body_weights contains NaN"),
])
def test_body_prior_needs_body_weights(garment, body_weights, message: str) -> None:
    model = build()
    pair = replace(make_pair(*garment, model.config), body_weights=body_weights)
    with pytest.raises(ValueError, match=message):
        model.encode([pair])


def test_unknown_prior_is_rejected() -> None:
    with pytest.raises(ValueError, match="weight_prior"):
        GarmentDeformer(tiny_config(weight_prior="smpl"))


def test_checkpoints_keep_their_prior(garment, tmp_path) -> None:
    """A checkpoint saved before ``weight_prior`` and ``weight_reach`` existed has no
    such keys (and no gate): it loads as ``none`` without a reach and predicts as before.
    A new one keeps its own prior and reach."""
    old = build(seed=3, weight_prior="none", weight_reach=None)
    payload = model_payload(old)
    del payload["model_config"]["weight_prior"], payload["model_config"]["weight_reach"]
    save_checkpoint(tmp_path / "old.pt", payload)
    loaded = load_model(tmp_path / "old.pt")
    assert loaded.config.weight_prior == "none" and loaded.config.weight_reach is None
    pair = make_pair(*garment, old.config)
    inputs = frame_inputs(old.config, 1, 2)
    assert torch.equal(old(old.encode([pair]), *inputs).posed,
                       loaded(loaded.encode([pair]), *inputs).posed)

    new = build(seed=3)
    with torch.no_grad():
        new.weight_head.gate.fill_(0.25)
    save_checkpoint(tmp_path / "new.pt", model_payload(new))
    reloaded = load_model(tmp_path / "new.pt")
    assert asdict(reloaded.config) == asdict(new.config)
    assert reloaded.weight_head.gate.item() == 0.25


def test_weight_reach_gives_far_joints_no_weight(garment) -> None:
    """However large the learned correction, a joint whose body region is out of
    reach gets exactly no weight; without a reach the same model gives it some."""
    from gnngarment.body.joint_reach import reachable_joints

    models = {reach: build(seed=4, weight_reach=reach) for reach in (None, 0.05)}
    pair = make_pair(*garment, models[None].config)
    inputs = frame_inputs(models[None].config, 1, 2)
    reachable = reachable_joints(pair.rest_pos, pair.body_weights, pair.joint_distances, 0.05)
    assert 0 < reachable.sum() < reachable.numel()
    far = ~reachable.repeat(2, 1)
    for reach, model in models.items():
        with torch.no_grad():
            model.weight_head.gate.fill_(5.0)
        weights = model(model.encode([pair]), *inputs).weights
        torch.testing.assert_close(weights.sum(-1), torch.ones(len(weights)))
        if reach is None:
            assert weights[far].max() > 1e-3
        else:
            assert weights[far].max() == 0


@pytest.mark.parametrize("reach", [-0.1, 0.0])
def test_bad_weight_reach_is_rejected(reach: float) -> None:
    with pytest.raises(ValueError, match="weight_reach must be positive"):
        GarmentDeformer(tiny_config(weight_reach=reach))
