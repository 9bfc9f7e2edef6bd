"""The deformer with oscillator dynamics: a warm start changes nothing, chunks equal one
pass, the state carries after the body stops, and training reaches the oscillators."""

from __future__ import annotations

import math

import pytest
import torch

from gnngarment.model import GarmentDeformer
from tests.meshes import random_disk
from tests.model.pairs import frame_inputs, make_pair, tiny_config

FPS = 30.0


def swing_then_stop(frames: int, moving: int) -> torch.Tensor:
    """``(frames, 24, 4, 4)``: every joint swings sideways (0.3 m at 1 Hz) for ``moving``
    frames, then holds its last pose."""
    t = torch.arange(frames, dtype=torch.float32).clamp(max=moving - 1) / FPS
    transforms = torch.eye(4).repeat(frames, 24, 1, 1)
    transforms[:, :, 0, 3] = 0.3 * torch.sin(2 * math.pi * t)[:, None]
    angle = 0.4 * torch.sin(2 * math.pi * t)
    transforms[:, :, 0, 0] = torch.cos(angle)[:, None]
    transforms[:, :, 0, 1] = -torch.sin(angle)[:, None]
    transforms[:, :, 1, 0] = torch.sin(angle)[:, None]
    transforms[:, :, 1, 1] = torch.cos(angle)[:, None]
    return transforms


def trained_like(model: GarmentDeformer, seed: int = 0) -> GarmentDeformer:
    """Give the oscillator head non-zero output weights (an untrained head has zero gain,
    under which every comparison below would hold trivially)."""
    generator = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        output = model.oscillator_head.output
        output.weight.copy_(torch.randn(output.weight.shape, generator=generator) * 0.5)
        output.bias.add_(torch.randn(output.bias.shape, generator=generator))
    return model


@pytest.fixture(scope="module")
def disk():
    return random_disk(120, 3)


def build(dynamics_modes: int, seed: int = 0) -> GarmentDeformer:
    torch.manual_seed(seed)
    model = GarmentDeformer(tiny_config(dynamics_modes=dynamics_modes))
    return model.eval()


def test_warm_start_from_a_model_without_dynamics_changes_nothing(disk, tmp_path) -> None:
    from gnngarment.training.trainer import warm_start

    plain = build(0)
    dynamic = build(3, seed=5)
    path = tmp_path / "plain.pt"
    from gnngarment.model.checkpoint import model_payload, save_checkpoint
    save_checkpoint(path, model_payload(plain))
    warm_start(dynamic, path)
    pair = make_pair(*disk, plain.config)
    motion, velocity, _ = frame_inputs(plain.config, 1, 6)
    transforms = swing_then_stop(20, 10)
    frames = torch.arange(14, 20)[None]
    with torch.no_grad():
        expected = plain(plain.encode([pair]), motion, velocity, transforms[frames])
        context = dynamic.encode([pair])
        offsets = dynamic.dynamic_blend_shapes(context, [transforms], frames, FPS)
        got = dynamic(context, motion, velocity, transforms[frames], offsets)
    assert torch.equal(offsets, torch.zeros_like(offsets))
    assert torch.allclose(got.posed, expected.posed, atol=1e-7)


def test_warm_start_refuses_weights_of_another_architecture(tmp_path) -> None:
    from gnngarment.model.checkpoint import model_payload, save_checkpoint
    from gnngarment.training.trainer import warm_start

    other = GarmentDeformer(tiny_config(processor_channels=8))
    path = tmp_path / "other.pt"
    save_checkpoint(path, model_payload(other))
    with pytest.raises(ValueError, match="shape"):
        warm_start(build(2), path)


@pytest.mark.parametrize("chunk", [1, 4, 7, 40])
def test_streaming_in_chunks_equals_one_pass(disk, chunk: int) -> None:
    model = trained_like(build(3))
    pair = make_pair(*disk, model.config)
    transforms = swing_then_stop(40, 25)
    with torch.no_grad():
        context = model.encode([pair])
        whole = model.dynamic_blend_shapes(context, [transforms], torch.arange(40)[None], FPS)
        stream = model.dynamics_stream(context, FPS)
        pieces = [stream.advance(transforms[start:start + chunk])
                  for start in range(0, 40, chunk)]
    streamed = torch.cat(pieces).flatten(0, 1)
    assert whole.abs().max() > 1e-4          # the comparison is not between zeros
    assert (streamed - whole).abs().max() < 1e-5


def test_the_garment_keeps_moving_after_the_body_stops(disk) -> None:
    model = trained_like(build(2))
    with torch.no_grad():
        # Lightly damped, slow modes: what a dress hem has.
        model.oscillator_head.output.bias[2:4] = -3.0     # damping near its minimum
    pair = make_pair(*disk, model.config)
    transforms = swing_then_stop(60, 20)
    with torch.no_grad():
        offsets = model.dynamic_blend_shapes(model.encode([pair]), [transforms],
                                             torch.arange(60)[None], FPS).view(60, -1, 3)
    # The body is still from frame 19 on; the oscillators are not.
    motion_after_stop = (offsets[21:] - offsets[20:-1]).norm(dim=-1).amax(dim=1)
    assert motion_after_stop[:10].max() > 1e-4
    # ... and they settle: damped, never growing.
    assert motion_after_stop[-10:].max() < motion_after_stop[:10].max()


def test_a_body_at_rest_drives_nothing(disk) -> None:
    model = trained_like(build(2))
    pair = make_pair(*disk, model.config)
    rest = torch.eye(4).repeat(12, 24, 1, 1)
    with torch.no_grad():
        offsets = model.dynamic_blend_shapes(model.encode([pair]), [rest],
                                             torch.arange(12)[None], FPS)
    assert offsets.abs().max() < 1e-6


def test_training_reaches_the_oscillators(disk) -> None:
    model = build(2)
    model.train()
    pair = make_pair(*disk, model.config)
    motion, velocity, _ = frame_inputs(model.config, 1, 5)
    transforms = swing_then_stop(30, 15)
    frames = torch.tensor([[3, 9, 16, 22, 29]])
    context = model.encode([pair])
    offsets = model.dynamic_blend_shapes(context, [transforms], frames, FPS)
    out = model(context, motion, velocity, transforms[frames], offsets)
    target = out.posed.detach() + 0.01
    ((out.posed - target) ** 2).mean().backward()
    # The zero-initialised output layer gets a gradient through the gain; every other
    # layer of the head joins once its output weights are non-zero (as the physics
    # submodule does).
    assert model.oscillator_head.output.weight.grad.abs().sum() > 0


def test_a_model_with_dynamics_needs_their_offsets(disk) -> None:
    model = build(2)
    pair = make_pair(*disk, model.config)
    motion, velocity, transforms = frame_inputs(model.config, 1, 2)
    with pytest.raises(ValueError, match="dynamic_offsets"):
        model(model.encode([pair]), motion, velocity, transforms)


@pytest.mark.parametrize("change, message", [
    ({"dynamics_modes": -1}, "dynamics_modes"),
    ({"dynamics_modes": 99}, "dynamics_modes"),
    ({"dynamics_modes": 2, "weight_prior": "none"}, "weight_prior"),
])
def test_inconsistent_dynamics_settings_are_refused(change, message) -> None:
    with pytest.raises(ValueError, match=message):
        tiny_config(**change)


def test_a_checkpoint_config_saved_before_dynamics_loads_without_them() -> None:
    from dataclasses import asdict

    from gnngarment.model.checkpoint import stored_model_config

    stored = asdict(tiny_config())
    del stored["dynamics_modes"]
    config = stored_model_config(stored)
    assert config.dynamics_modes == 0
    assert not GarmentDeformer(config).has_dynamics
