"""Integrated gradients on the graph features (paper Eq. 9)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from gnngarment.attribution import FeatureResponse, FrameInputs, attribute, influence_field
from tests.attribution.conftest import TARGET, build


def completeness_error(result) -> float:
    """|ΣR − (f(X) − f(0))| relative to f(X) − f(0), from our own two evaluations,
    less the float32 round-off of f itself (~1e-7 |f|, which matters when f(X) − f(0)
    is small next to f, as for posed positions)."""
    change = result.value - result.baseline_value
    error = abs(float(result.attributions.sum()) - change)
    return max(error - 1e-6 * abs(result.value), 0.0) / abs(change)


def test_completeness_single_level(single_level) -> None:
    _, result = single_level
    assert result.attributions.shape == (144, 30)
    assert result.value != result.baseline_value
    assert completeness_error(result) < 1e-4
    assert abs(result.delta) < 1e-4 * abs(result.value - result.baseline_value)
    assert result.relative_delta < 1e-4


def test_completeness_multilevel(multilevel) -> None:
    _, result = multilevel
    assert completeness_error(result) < 1e-4
    assert result.relative_delta < 1e-4


def test_completeness_region_all_and_posed(pair, frame) -> None:
    model = build(levels=2, seed=1)
    # Untrained, the body-prior head is exactly body skinning and the blend shapes are
    # ~1e-7 m: the posed output would not depend on the features. Open the gate as
    # training does.
    with torch.no_grad():
        model.weight_head.gate.fill_(1.0)
    region = attribute(model, pair, frame, target="region", target_vertices=[3, 40, 41, 130],
                       reduction="sum", n_steps=12)
    everything = attribute(model, pair, frame, target="all", output="posed", n_steps=12)
    for result in (region, everything):
        assert completeness_error(result) < 1e-3
    assert region.target_vertices.tolist() == [3, 40, 41, 130]
    assert everything.target_vertices.tolist() == list(range(144))


def test_gauss_legendre_is_eq9(pair, frame) -> None:
    """With N_s = 2 the quadrature can be written out: nodes ½(1 + ξ_k), ξ = ∓1/√3,
    weights ½ each on [0, 1]; R = X ⊙ Σ_k w_k ∂f(α_k X)/∂X."""
    model = build(levels=2)
    result = attribute(model, pair, frame, target="vertex", target_vertices=TARGET, n_steps=2)
    vertices = torch.tensor([TARGET])
    response = FeatureResponse(model, pair, FrameInputs.coerce(frame, model.config), vertices)
    nodes, weights = np.polynomial.legendre.leggauss(2)
    x = pair.features[None]
    expected = torch.zeros_like(x)
    for node, weight in zip(nodes, weights, strict=True):
        scaled = (0.5 * (1 + node) * x).requires_grad_()
        (gradient,) = torch.autograd.grad(response(scaled).sum(), scaled)
        expected += 0.5 * weight * gradient
    expected = (x * expected)[0].numpy()
    np.testing.assert_allclose(result.attributions, expected, rtol=1e-4,
                               atol=1e-6 * np.abs(expected).max())


def test_batched_quadrature_points_are_independent(pair, frame) -> None:
    """Several quadrature points share one block-diagonal graph; the result must not
    depend on how many run together."""
    model = build(levels=2)
    one = attribute(model, pair, frame, target_vertices=TARGET, n_steps=4,
                    internal_batch_size=1)
    six = attribute(model, pair, frame, target_vertices=TARGET, n_steps=4,
                    internal_batch_size=4)
    np.testing.assert_allclose(one.attributions, six.attributions, rtol=1e-4,
                               atol=1e-6 * np.abs(one.attributions).max())


def test_single_level_field_is_local(single_level, pair) -> None:
    """levels=0: E^gg (3 GAT blocks) and the processor's embedding + output GATs see 5
    hops, so nothing beyond is attributed at all, and 90% of the mass is within 3."""
    model, result = single_level
    receptive = len(model.config.garment_channels) + 2
    field = influence_field(result.heat(), pair.rest_pos.numpy(), pair.hierarchy.edge_index,
                            TARGET)
    assert field.support_hops == receptive == 5
    assert field.hops <= 3
    assert field.support < 144 - 2 * 8               # the rings 6+ hops away stay out


def test_multilevel_field_reaches_farther(single_level, multilevel, pair) -> None:
    pos, edges = pair.rest_pos.numpy(), pair.hierarchy.edge_index
    fields = {}
    for name, (_, result) in (("single", single_level), ("multi", multilevel)):
        heat = result.heat()
        fields[name] = (influence_field(heat, pos, edges, TARGET),
                        influence_field(heat, pos, edges, TARGET, mass=0.99))
    (single90, single99), (multi90, multi99) = fields["single"], fields["multi"]
    assert multi90.support_hops > single90.support_hops + 2
    assert multi90.support > 1.5 * single90.support
    assert multi99.count > single99.count
    assert multi99.radius > single99.radius


def test_model_mode_restored_and_inference_mode_caller(pair, frame) -> None:
    model = build(levels=0)
    model.train()
    with torch.inference_mode():
        result = attribute(model, pair, frame, target_vertices=TARGET, n_steps=3)
    assert model.training
    assert np.isfinite(result.attributions).all() and np.abs(result.attributions).sum() > 0


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"target_vertices": 144}, "target vertex 144 is out of range for a garment of 144"),
    ({"target_vertices": -1}, "target vertex -1 is out of range"),
    ({"target": "face", "target_vertices": 3}, "unknown target kind 'face'"),
    ({"target": "vertex", "target_vertices": [1, 2]}, "exactly one vertex"),
    ({"target": "vertex"}, "target 'vertex' needs target_vertices"),
    ({"target": "region", "target_vertices": []}, "integer vertex indices"),
    ({"target": "region", "target_vertices": [4, 4]}, "duplicates"),
    ({"target": "region", "target_vertices": [0.5]}, "integer vertex indices"),
    ({"target": "all", "target_vertices": 3}, "target 'all' takes no target_vertices"),
    ({"target_vertices": 3, "output": "weights"}, "unknown output 'weights'"),
    ({"target_vertices": 3, "reduction": "max"}, "unknown reduction 'max'"),
    ({"target_vertices": 3, "n_steps": 0}, "n_steps must be an integer in 1..1000"),
    ({"target_vertices": 3, "internal_batch_size": 0}, "internal_batch_size must be >= 1"),
])
def test_bad_arguments(pair, frame, kwargs, message) -> None:
    with pytest.raises(ValueError, match=message):
        attribute(build(levels=0), pair, frame, **kwargs)


def test_bad_frame_and_pair(pair, frame) -> None:
    model = build(levels=0)
    motion, velocity, transforms = frame
    with pytest.raises(ValueError, match="velocity_window must have shape"):
        attribute(model, pair, (motion, velocity[..., :-3], transforms), target_vertices=3)
    with pytest.raises(ValueError, match="joint_transforms contains NaN"):
        attribute(model, pair, (motion, velocity, transforms * float("nan")),
                  target_vertices=3)
    with pytest.raises(ValueError, match=r"pair.features must have shape \(144, 30\)"):
        attribute(model, replace(pair, features=pair.features[:, :29]), frame,
                  target_vertices=3)

