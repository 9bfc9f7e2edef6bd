"""The fused graph-attention operator against the PyTorch path (its reference)."""

from __future__ import annotations

import pytest
import torch

from gnngarment.model import fused_attention
from gnngarment.model.attention_graph import AttentionGraph
from gnngarment.model.fused_attention import (
    attention_path,
    fallback_reason,
    fused_graph_attention,
    use_attention_path,
)
from gnngarment.model.graph_attention import GraphAttention
from tests.model.attention_cases import assert_relative, random_graph

pytestmark = pytest.mark.skipif(
    not fused_attention._load(),
    reason=f"fused attention operator unavailable: {fused_attention._state.get('reason')}")

LAYOUTS = [(1, True), (4, True), (1, False), (4, False)]


def seeded_layer(heads: int, concat: bool, in_channels: int = 6, out_channels: int = 5,
                 dtype: torch.dtype = torch.float32) -> GraphAttention:
    torch.manual_seed(heads + 10 * concat)
    layer = GraphAttention(in_channels, out_channels, heads=heads, concat=concat)
    with torch.no_grad():  # a non-zero bias and attention large enough to matter
        layer.bias.normal_()
        layer.att_src.mul_(3)
        layer.att_dst.mul_(3)
    return layer.to(dtype)


def run(layer: GraphAttention, x: torch.Tensor, graph, path: str
        ) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    """Output and the gradients of a fixed weighted sum of it, on ``path``."""
    x = x.clone().requires_grad_(True)
    layer.zero_grad(set_to_none=True)
    with use_attention_path(path):
        out = layer(x, graph)
    weight = torch.linspace(-1, 2, out.numel(), dtype=out.dtype).view_as(out)
    (out * weight).sum().backward()
    grads = {"x": x.grad, **{name: p.grad for name, p in layer.named_parameters()}}
    return out.detach(), grads


@pytest.mark.parametrize(("heads", "concat"), LAYOUTS)
def test_forward_and_gradients_match_the_pytorch_path(heads: int, concat: bool) -> None:
    layer = seeded_layer(heads, concat)
    graph = AttentionGraph.from_edge_index(random_graph(heads), 60)  # 15 isolated nodes
    x = torch.randn(60, 6, generator=torch.Generator().manual_seed(1))
    reference, reference_grads = run(layer, x, graph, "pytorch")
    out, grads = run(layer, x, graph, "fused")
    assert_relative(out, reference, 1e-6, "output")
    for name, grad in reference_grads.items():
        assert_relative(grads[name], grad, 1e-5, name)


@pytest.mark.parametrize(("heads", "concat"), LAYOUTS)
def test_inference_mode_and_no_grad_match(heads: int, concat: bool) -> None:
    layer = seeded_layer(heads, concat)
    graph = AttentionGraph.from_edge_index(random_graph(3), 60)
    x = torch.randn(60, 6, generator=torch.Generator().manual_seed(2))
    with use_attention_path("pytorch"), torch.no_grad():
        reference = layer(x, graph)
    with use_attention_path("fused"):
        with torch.inference_mode():
            inferred = layer(x, graph)
        with torch.no_grad():
            plain = layer(x, graph)
    assert_relative(inferred, reference, 1e-6, "inference_mode")
    assert torch.equal(inferred, plain)


def test_repeated_copies_match_the_flat_graph() -> None:
    """A graph of stacked frames (blocks, mixed garments) gives what its flat edge list
    gives, forward and backward."""
    one = AttentionGraph.from_edge_index(random_graph(5, num_nodes=20, connected=16,
                                                      edges=60), 20)
    other = AttentionGraph.from_edge_index(random_graph(6, num_nodes=9, connected=9,
                                                        edges=20), 9)
    stacked = AttentionGraph.repeated([(one, 3), (other, 2)])
    flat = AttentionGraph.from_edge_index(stacked.edge_index, stacked.num_nodes)
    layer = seeded_layer(4, False)
    x = torch.randn(stacked.num_nodes, 6, generator=torch.Generator().manual_seed(3))
    reference, reference_grads = run(layer, x, flat, "pytorch")
    out, grads = run(layer, x, stacked, "fused")
    assert_relative(out, reference, 1e-6, "output")
    for name, grad in reference_grads.items():
        assert_relative(grads[name], grad, 1e-5, name)


def test_isolated_vertices_and_rows_of_one_edge() -> None:
    """Self loop only: the output is the node's own projected features plus the bias;
    a row of one further edge splits its weight between two sources."""
    edge_index = torch.tensor([[0], [1]])  # 0 -> 1; nodes 2, 3 isolated
    graph = AttentionGraph.from_edge_index(edge_index, 4)
    layer = seeded_layer(4, True, in_channels=3, out_channels=2)
    x = torch.randn(4, 3, generator=torch.Generator().manual_seed(4))
    reference, reference_grads = run(layer, x, graph, "pytorch")
    out, grads = run(layer, x, graph, "fused")
    own = x @ layer.lin.weight.detach().t() + layer.bias.detach()
    torch.testing.assert_close(out[[0, 2, 3]], own[[0, 2, 3]])
    assert_relative(out, reference, 1e-6, "output")
    for name, grad in reference_grads.items():
        assert_relative(grads[name], grad, 1e-5, name)


@pytest.mark.parametrize(("heads", "concat"), LAYOUTS)
def test_gradcheck_float64(heads: int, concat: bool) -> None:
    graph = AttentionGraph.from_edge_index(random_graph(7, num_nodes=9, connected=7,
                                                        edges=16), 9)
    generator = torch.Generator().manual_seed(heads)
    channels = 3
    h = torch.randn(9, heads * channels, dtype=torch.float64, generator=generator)
    a_src = torch.randn(9, heads, dtype=torch.float64, generator=generator)
    a_dst = torch.randn(9, heads, dtype=torch.float64, generator=generator)
    bias = torch.randn(heads * channels if concat else channels, dtype=torch.float64,
                       generator=generator)
    inputs = tuple(t.requires_grad_(True) for t in (h, a_src, a_dst, bias))

    def function(h, a_src, a_dst, bias):
        return fused_graph_attention(h, a_src, a_dst, bias, graph, 0.2, concat)

    assert torch.autograd.gradcheck(function, inputs)


def test_deterministic_across_runs_and_threads() -> None:
    """The operator's outputs and gradients are bitwise the same for 1 and 2 threads
    (every element is written by one thread in a fixed order). Tested on the operator's
    own inputs: the projection GEMM around it is BLAS's, whose rounding may depend on
    the thread count."""
    stacked = AttentionGraph.repeated([(AttentionGraph.from_edge_index(
        random_graph(8, num_nodes=300, connected=280, edges=1500), 300), 4)])
    generator = torch.Generator().manual_seed(5)
    rows, heads, channels = stacked.num_nodes, 4, 8
    tensors = (torch.randn(rows, heads * channels, generator=generator),
               torch.randn(rows, heads, generator=generator),
               torch.randn(rows, heads, generator=generator),
               torch.randn(channels, generator=generator))
    weight = torch.randn(rows, channels, generator=generator)
    threads = torch.get_num_threads()
    results = []
    try:
        for count in (1, 2, 1, 2):
            torch.set_num_threads(count)
            inputs = [t.clone().requires_grad_(True) for t in tensors]
            out = fused_graph_attention(*inputs, stacked, 0.2, False)
            (out * weight).sum().backward()
            results.append([out.detach()] + [t.grad for t in inputs])
    finally:
        torch.set_num_threads(threads)
    for other in results[1:]:
        for first, again in zip(results[0], other, strict=True):
            assert torch.equal(first, again)


def test_path_choice_and_its_reason(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(fused_attention.PATH_VARIABLE, raising=False)
    assert attention_path() == "fused" and fallback_reason() is None
    monkeypatch.setenv(fused_attention.PATH_VARIABLE, "pytorch")
    assert attention_path() == "pytorch"
    assert "GNNGARMENT_ATTENTION=pytorch" in fallback_reason()
    with use_attention_path("fused"):
        assert attention_path(grad=True) == "fused"
    with pytest.raises(ValueError, match="attention path"), use_attention_path("cuda"):
        pass


def test_bad_inputs_are_rejected() -> None:
    graph = AttentionGraph.from_edge_index(random_graph(9), 60)
    h = torch.randn(60, 8)
    scores = torch.randn(59, 4)
    with pytest.raises(RuntimeError, match="rows"):
        torch.ops.gnngarment.graph_attention_forward(
            [graph.ptr], [graph.source], [1], h, scores, scores, torch.zeros(2), 0.2, False)


def test_a_machine_without_a_compiler_runs_the_pytorch_path(tmp_path) -> None:
    """No compiler and no cached library: the fallback, with the reason, and the layer
    still runs (a fresh process: the operator is loaded once per process)."""
    import os
    import subprocess
    import sys

    code = (
        "import torch\n"
        "from gnngarment.model import fused_attention as f\n"
        "from gnngarment.model.attention_graph import AttentionGraph\n"
        "from gnngarment.model.graph_attention import GraphAttention\n"
        "print(f.attention_path(), '|', f.fallback_reason())\n"
        "graph = AttentionGraph.from_edge_index(torch.tensor([[0, 1], [1, 2]]), 3)\n"
        "print(tuple(GraphAttention(4, 2, heads=2)(torch.randn(3, 4), graph).shape))\n")
    env = {key: value for key, value in os.environ.items() if key != "CXX"}
    env.update(PATH=str(tmp_path), GNNGARMENT_EXTENSION_DIR=str(tmp_path / "cache"),
               GNNGARMENT_ATTENTION="auto")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    first, shape = done.stdout.strip().splitlines()
    assert first.startswith("pytorch | RuntimeError: no C++ compiler found")
    assert shape == "(3, 4)"
