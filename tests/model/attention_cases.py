"""Tiny graphs and seeded GraphAttention/GATConv pairs shared by the attention tests."""

from __future__ import annotations

import torch
from torch_geometric.nn import GATConv

from gnngarment.model.graph_attention import GraphAttention

TOLERANCE = dict(rtol=1e-5, atol=1e-6)


def assert_relative(actual: torch.Tensor, expected: torch.Tensor, tolerance: float,
                    name: str) -> None:
    """``max |actual − expected| <= tolerance · max |expected|`` (normwise relative)."""
    error = float((actual - expected).abs().max())
    scale = float(expected.abs().max())
    assert error <= tolerance * scale, f"{name}: {error:.2e} vs max {scale:.2e}"


def random_graph(seed: int, num_nodes: int = 60, connected: int = 45, edges: int = 300
                 ) -> torch.Tensor:
    """Edges among the first ``connected`` nodes only (the rest are isolated), in two
    components, with self loops and repeated edges (as a multigraph can have)."""
    generator = torch.Generator().manual_seed(seed)
    half = connected // 2
    a = torch.randint(0, half, (2, edges // 2), generator=generator)
    b = torch.randint(half, connected, (2, edges - edges // 2), generator=generator)
    edge_index = torch.cat([a, b, a[:, :10]], dim=1)  # repeated edges
    loops = torch.arange(0, connected, 7).repeat(2, 1)
    return torch.cat([edge_index, loops], dim=1)


def pair_of_layers(in_channels: int, out_channels: int, heads: int, concat: bool,
                   seed: int = 0) -> tuple[GATConv, GraphAttention]:
    torch.manual_seed(seed)
    reference = GATConv(in_channels, out_channels, heads=heads, concat=concat)
    torch.manual_seed(seed)
    layer = GraphAttention(in_channels, out_channels, heads=heads, concat=concat)
    with torch.no_grad():  # a non-zero bias, so that its gradient path is exercised too
        reference.bias.normal_()
        layer.bias.copy_(reference.bias)
    return reference, layer


def outputs_and_gradients(layer: torch.nn.Module, x: torch.Tensor, graph,
                          weight: torch.Tensor) -> dict[str, torch.Tensor]:
    x = x.clone().requires_grad_(True)
    layer.zero_grad(set_to_none=True)
    out = layer(x, graph)
    (out * weight).sum().backward()
    result = {"out": out.detach(), "x.grad": x.grad}
    result.update({f"{name}.grad": p.grad for name, p in layer.named_parameters()})
    return result
