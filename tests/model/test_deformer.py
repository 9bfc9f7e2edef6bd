"""Properties of the full deformer that would catch real mistakes."""

from __future__ import annotations

import io
from dataclasses import asdict, replace

import numpy as np
import pytest
import torch

from gnngarment.config import load_config
from gnngarment.model import POOLING_METHODS, GarmentDeformer, ModelConfig, stack_hierarchies
from gnngarment.paths import SHIPPED_MODEL, default_config
from tests.meshes import interleave, random_disk, tube
from tests.model.pairs import frame_inputs, make_pair, tiny_config


def build(config: ModelConfig, seed: int = 0) -> GarmentDeformer:
    torch.manual_seed(seed)
    model = GarmentDeformer(config)
    model.eval()
    return model


def run(model, pairs, frames=2, seed=0):
    context = model.encode(pairs)
    return model(context, *frame_inputs(model.config, len(pairs), frames, seed))


@pytest.fixture(scope="module")
def garments():
    return {"disk": random_disk(150, 11), "tube": tube(8, 10, twist=0.3)}


def test_weights_are_a_distribution_and_shapes_match(garments) -> None:
    config = tiny_config()
    model = build(config)
    pairs = [make_pair(*garments["disk"], config), make_pair(*garments["tube"], config)]
    out = run(model, pairs, frames=3)
    total = 3 * (150 + 80)
    assert out.weights.shape == (total, 24) and out.posed.shape == (total, 3)
    assert (out.weights >= 0).all()
    torch.testing.assert_close(out.weights.sum(-1), torch.ones(total))
    assert out.item_ptr.tolist()[-1] == total and out.item.max() == 5


def test_identity_transforms_give_rest_plus_blend_shapes(garments) -> None:
    config = tiny_config()
    model = build(config)
    pair = make_pair(*garments["disk"], config)
    context = model.encode([pair])
    motion, velocity, _ = frame_inputs(config, 1, 2)
    out = model(context, motion, velocity, torch.eye(4).repeat(1, 2, 24, 1, 1))
    torch.testing.assert_close(out.posed, pair.rest_pos.repeat(2, 1) + out.blend_shapes)


def test_relabelling_vertices_permutes_outputs(garments) -> None:
    config = tiny_config()
    model = build(config)
    pos, faces = garments["disk"]  # irregular: no eccentricity or landmark ties
    permuted_pos, permuted_faces = interleave(pos, faces, seed=3)
    permutation = np.array([np.flatnonzero((pos == p).all(1))[0] for p in permuted_pos])

    original = run(model, [make_pair(pos, faces, config)])
    relabelled = run(model, [make_pair(permuted_pos, permuted_faces, config)])

    n = len(pos)
    for name in ("weights", "blend_shapes", "posed"):
        a = getattr(original, name).view(2, n, -1)[:, permutation]
        b = getattr(relabelled, name).view(2, n, -1)
        torch.testing.assert_close(a, b, atol=2e-5, rtol=1e-4)


def test_a_batch_of_two_garments_equals_one_by_one(garments) -> None:
    config = tiny_config()
    model = build(config)
    pairs = [make_pair(*garments["disk"], config, seed=1),
             make_pair(*garments["tube"], config, seed=2)]
    motion, velocity, transforms = frame_inputs(config, 2, 3, seed=5)
    together = model(model.encode(pairs), motion, velocity, transforms)
    sizes = [150, 80]
    for p, pair in enumerate(pairs):
        alone = model(model.encode([pair]), motion[p:p + 1], velocity[p:p + 1],
                      transforms[p:p + 1])
        for name in ("weights", "blend_shapes", "posed"):
            torch.testing.assert_close(together.split(name, sizes, 3)[p],
                                       alone.split(name, [sizes[p]], 3)[0],
                                       atol=1e-5, rtol=1e-4)


def test_seeded_construction_is_deterministic(garments) -> None:
    config = tiny_config()
    pairs = [make_pair(*garments["tube"], config)]
    a = run(build(config, seed=4), pairs)
    b = run(build(config, seed=4), pairs)
    c = run(build(config, seed=5), pairs)
    assert torch.equal(a.posed, b.posed)
    assert not torch.equal(a.posed, c.posed)


def test_saved_and_reloaded_model_gives_identical_outputs(garments) -> None:
    config = tiny_config()
    model = build(config, seed=1)
    pairs = [make_pair(*garments["disk"], config)]
    buffer = io.BytesIO()
    torch.save({"config": asdict(config), "state": model.state_dict()}, buffer)
    buffer.seek(0)
    saved = torch.load(buffer, weights_only=True)
    reloaded = build(ModelConfig(**saved["config"]), seed=99)
    reloaded.load_state_dict(saved["state"])
    reloaded.eval()
    assert torch.equal(run(model, pairs).posed, run(reloaded, pairs).posed)


def test_every_parameter_is_trained_by_its_stage(garments) -> None:
    # The paper's head: with the body prior, E^t1 joins after the first step
    # (tests/model/test_skinning_weight_head.py).
    config = tiny_config(weight_prior="none")
    model = build(config)
    model.train()
    pairs = [make_pair(*garments["disk"], config)]
    target = torch.randn(2 * 150, 3)

    # Stage 1: a supervised loss reaches every parameter except the physics submodule.
    out = run(model, pairs)
    ((out.posed - target) ** 2).mean().backward()
    for name, parameter in model.named_parameters():
        if name.startswith("physics_processor"):
            assert parameter.grad is None, name
        else:
            assert parameter.grad is not None and parameter.grad.abs().sum() > 0, name

    # Stage 2: only the physics submodule trains. Its output layer starts at zero (so
    # the stage starts from the supervised solution): after one step every one of its
    # parameters receives a gradient.
    model.zero_grad(set_to_none=True)
    model.use_physics = True
    physics = [p for n, p in model.named_parameters() if n.startswith("physics_processor")]
    optimiser = torch.optim.Adamax(physics, lr=1e-2)
    for _ in range(2):
        optimiser.zero_grad(set_to_none=True)
        out = run(model, pairs)
        out.posed[:, 2].sum().backward()  # a gravity-like physics objective
        optimiser.step()
    for name, parameter in model.named_parameters():
        if name.startswith("physics_processor"):
            assert parameter.grad is not None and parameter.grad.abs().sum() > 0, name


def test_physics_submodule_starts_at_zero(garments) -> None:
    config = tiny_config()
    model = build(config)
    pairs = [make_pair(*garments["tube"], config)]
    before = run(model, pairs).posed
    model.use_physics = True
    torch.testing.assert_close(run(model, pairs).posed, before)


@pytest.mark.parametrize("pooling", POOLING_METHODS)
@pytest.mark.parametrize("levels", [0, 1, 2, 3])
def test_variants_build_and_run(garments, pooling: str, levels: int) -> None:
    config = tiny_config(pooling=pooling, levels=levels, physics_submodule=levels % 2 == 0)
    model = build(config)
    model.use_physics = True
    pairs = [make_pair(*garments["disk"], config), make_pair(*garments["tube"], config)]
    out = run(model, pairs)
    assert out.posed.shape == (2 * 230, 3) and torch.isfinite(out.posed).all()
    out.posed.sum().backward()


@pytest.mark.parametrize("change,message", [
    (dict(style_channels=[32, 8]), "style_channels"),
    (dict(motion_hidden=8), "motion_hidden"),
    (dict(pooling="mean"), "pooling"),
    (dict(levels=-1), "levels"),
    (dict(garment_channels=[16]), "garment_channels"),
])
def test_inconsistent_configs_are_rejected(change, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        GarmentDeformer(replace(tiny_config(), **change))


def test_bad_inputs_name_the_field(garments) -> None:
    config = tiny_config()
    model = build(config)
    pair = make_pair(*garments["disk"], config)
    with pytest.raises(ValueError, match="descriptor has shape"):
        model.encode([replace(pair, descriptor=torch.zeros(5))])
    with pytest.raises(ValueError, match="features contains NaN"):
        model.encode([replace(pair, features=pair.features.clone().fill_(float("nan")))])
    context = model.encode([pair])
    motion, velocity, transforms = frame_inputs(config, 1, 2)
    with pytest.raises(ValueError, match="velocity_windows"):
        model(context, motion, velocity[..., :-1], transforms)
    with pytest.raises(ValueError, match="joint_transforms"):
        model(context, motion, velocity, transforms[:, :1])


@pytest.mark.parametrize("name", ["paper.yaml", "small.yaml"])
def test_shipped_model_configs_load_and_validate(name: str) -> None:
    config = load_config(default_config(f"model/{name}"), ModelConfig)
    config.validate()
    if name == "paper.yaml":
        assert asdict(config) == asdict(ModelConfig())


def reference_forward(model: GarmentDeformer, context, inputs):
    """The forward without either inference shortcut: M^mp reads every input column,
    and the frames' attention graphs are built as one plain edge list."""
    frames = inputs[0].shape[1]
    plain = replace(context, active_channels=None)
    plain._graphs = {}
    graph = stack_hierarchies([h for h in context.hierarchies for _ in range(frames)],
                              model.config.levels)
    graph.runs = []
    plain._graphs[frames] = graph
    return model(plain, *inputs)


def test_zero_columns_and_shared_frame_structure_change_nothing(garments) -> None:
    # Both shortcuts of the per-frame pass (skipping X^fuse's all-zero columns; one
    # copy's indices for every frame's edge softmax) give the reference's outputs and,
    # in training, its gradients, for a batch of two garments × three frames.
    model = build(tiny_config())
    model.train()
    model.use_physics = True
    with torch.no_grad():
        model.physics_processor.output.lin.weight.normal_(std=0.1)
    pairs = [make_pair(*garments["disk"], model.config),
             make_pair(*garments["tube"], model.config, seed=1)]
    inputs = frame_inputs(model.config, 2, 3)
    context = model.encode(pairs)
    assert context.active_channels is not None  # the shortcut is exercised
    assert len(context.active_channels) < context.fused[0].numel()
    actual = model(context, *inputs)
    actual_grads = torch.autograd.grad(actual.posed.square().sum(), list(model.parameters()),
                                       allow_unused=True)
    context = model.encode(pairs)
    expected = reference_forward(model, context, inputs)
    expected_grads = torch.autograd.grad(expected.posed.square().sum(),
                                         list(model.parameters()), allow_unused=True)
    for name in ("posed", "weights", "blend_shapes"):
        torch.testing.assert_close(getattr(actual, name), getattr(expected, name),
                                   rtol=1e-5, atol=1e-6, msg=name)
    for (name, _), a, e in zip(model.named_parameters(), actual_grads, expected_grads,
                               strict=True):
        if e is None:
            assert a is None or not a.any(), name
        else:
            torch.testing.assert_close(a, e, rtol=1e-4, atol=1e-6, msg=name)


def test_shipped_model_posed_vertices_equal_the_reference_path() -> None:
    # Issue 14's bar: the fast inference path poses the vertices of the shipped model
    # within 1e-5 m of the reference path (16 frames of a 3,000-vertex skirt).
    from data_prep.garments.skirt import flared_skirt
    from gnngarment.model.checkpoint import load_model

    model = load_model(SHIPPED_MODEL)
    model.use_physics = True
    pos, faces = flared_skirt(3000)
    pair = make_pair(pos, faces, model.config, levels=model.config.levels)
    inputs = frame_inputs(model.config, 1, 16)
    with torch.inference_mode():
        context = model.encode([pair])
        actual = model(context, *inputs).posed
        expected = reference_forward(model, model.encode([pair]), inputs).posed
    assert float((actual - expected).abs().max()) < 1e-5


def test_motion_reach_hides_the_joints_that_cannot_move_the_garment(garments) -> None:
    """With ``motion_reach`` no output depends on the rotation of a joint the weight reach
    keeps from every vertex, nor on the velocities of body vertices nearest to it; a
    joint in reach still changes the output."""
    config = tiny_config(motion_reach=True)
    model = build(config)
    pair = make_pair(*garments["disk"], config)
    context = model.encode([pair])
    seen = torch.isfinite(context.prior_logits).any(0)
    assert 0 < int(seen.sum()) < 24
    hidden, shown = int((~seen).nonzero()[0]), int(seen.nonzero()[0])
    motion, velocity, transforms = frame_inputs(config, 1, 3)
    reference = model(context, motion, velocity, transforms)

    def posed_after(joint: int) -> torch.Tensor:
        changed_motion = motion.clone()
        changed_motion[..., 3 * joint:3 * joint + 3] += 0.5
        nearest = pair.body_distances.argmin(1) == joint
        changed_velocity = velocity.clone().view(1, 3, config.window, -1, 3)
        changed_velocity[..., nearest, :] += 1.0
        return model(context, changed_motion, changed_velocity.view_as(velocity),
                     transforms).posed

    torch.testing.assert_close(posed_after(hidden), reference.posed, rtol=0, atol=0)
    assert (posed_after(shown) - reference.posed).abs().max() > 1e-6
    for no_reach in (dict(weight_prior="none"), dict(weight_reach=None)):
        assert build(tiny_config(**no_reach)).encode([pair]).motion_mask is None
