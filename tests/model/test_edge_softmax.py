"""The edge softmax's shift keeps exp in range and the layer equal to GATConv."""

from __future__ import annotations

import pytest
import torch

from gnngarment.model.attention_graph import AttentionGraph
from gnngarment.model.edge_softmax import _MAX_SHIFT_GAP, _softmax_shift, edge_softmax
from tests.model.attention_cases import (
    assert_relative,
    outputs_and_gradients,
    pair_of_layers,
    random_graph,
)


@pytest.mark.parametrize("scale", [1.0, 10.0, 30.0])
def test_large_logits_keep_matching(scale: float) -> None:
    # Scaled attention vectors spread the logits far beyond the cheap shift's accepted
    # gap (scale 10: ~35, 30: ~105): the exact segment max must then be used, and
    # nothing may underflow or overflow. Sums of near one-hot softmaxes round
    # differently, so compare normwise.
    reference, layer = pair_of_layers(6, 4, 4, concat=False)
    with torch.no_grad():
        for module in (reference, layer):
            module.att_src.mul_(scale)
            module.att_dst.mul_(scale)
    edge_index = random_graph(seed=3)
    x = torch.randn(60, 6, generator=torch.Generator().manual_seed(4))
    weight = torch.randn(60, 4, generator=torch.Generator().manual_seed(5))
    expected = outputs_and_gradients(reference, x, edge_index, weight)
    actual = outputs_and_gradients(layer, x, edge_index, weight)
    for name in expected:
        assert torch.isfinite(actual[name]).all(), name
        assert_relative(actual[name], expected[name], 1e-5, name)


@pytest.mark.parametrize("case", ["none", "bound", "exact"])
def test_softmax_shift_keeps_exp_in_range(case: str) -> None:
    graph = AttentionGraph.from_edge_index(random_graph(seed=8), 60)
    layout = graph.layout(3)
    generator = torch.Generator().manual_seed(9)
    a_src = torch.randn(60, 3, generator=generator)
    a_dst = torch.randn(60, 3, generator=generator)
    if case == "bound":   # large logits of small spread: shift by the cheap bound
        a_src += 100
    if case == "exact":   # widely spread logits: the exact segment max is needed
        a_src *= 100
        a_dst *= 100
    logits = torch.nn.functional.leaky_relu(
        a_src.reshape(-1)[layout.source_slot.long()]
        + a_dst.reshape(-1)[layout.target_slot.long()], 0.2)
    exact = torch.full((180,), -torch.inf).scatter_reduce(
        0, layout.target_slot.long(), logits, "amax")
    shift = _softmax_shift(torch.cat([a_src, a_dst, a_src + a_dst], dim=1), 3, layout, 0.2)
    assert (shift is None) == (case == "none")
    if shift is None:
        assert exact.max() <= 60 and exact.min() >= -_MAX_SHIFT_GAP
        return
    assert (shift >= exact).all()                      # exp never overflows
    assert (shift - exact).max() <= _MAX_SHIFT_GAP     # denominators stay >= e^-20
    if case == "exact":
        torch.testing.assert_close(shift, exact, rtol=0, atol=0)


@pytest.mark.parametrize("grad", [False, True])
def test_repeated_blocks_give_the_same_coefficients(grad: bool) -> None:
    # Gathering every copy with one copy's indices is a different computation of the
    # same coefficients, with and without autograd.
    first, second = random_graph(seed=1), random_graph(seed=2, num_nodes=30, connected=20,
                                                          edges=80)
    base = [(AttentionGraph.from_edge_index(first, 60), 3),
            (AttentionGraph.from_edge_index(second, 30), 2)]
    repeated = AttentionGraph.repeated(base)
    plain = AttentionGraph.from_edge_index(repeated.edge_index, repeated.num_nodes)
    heads = 3
    scores = torch.randn(240, 3 * heads, generator=torch.Generator().manual_seed(7))
    scores[:, 2 * heads:] = scores[:, :heads] + scores[:, heads:2 * heads]
    scores.requires_grad_(grad)
    with torch.set_grad_enabled(grad):
        expected = edge_softmax(scores, heads, plain.layout(heads), 0.2)
        actual = edge_softmax(scores, heads, repeated.layout(heads), 0.2,
                              repeated.block_layouts(heads))
    torch.testing.assert_close(actual, expected, rtol=1e-6, atol=1e-7)
    if grad:
        weight = torch.randn(expected.shape, generator=torch.Generator().manual_seed(8))
        (expected_grad,) = torch.autograd.grad((expected * weight).sum(), scores)
        (actual_grad,) = torch.autograd.grad((actual * weight).sum(), scores)
        torch.testing.assert_close(actual_grad, expected_grad, rtol=1e-5, atol=1e-6)
    with pytest.raises(ValueError, match="blocks cover"):
        edge_softmax(scores.detach()[:180], heads, plain.layout(heads), 0.2,
                     repeated.block_layouts(heads))
