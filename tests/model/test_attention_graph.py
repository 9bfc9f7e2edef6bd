"""AttentionGraph: self loops, edge order and validation, checked through GATConv."""

from __future__ import annotations

import pytest
import torch

from gnngarment.model.attention_graph import AttentionGraph
from tests.model.attention_cases import TOLERANCE, pair_of_layers, random_graph


def test_structure_round_trips_to_gatconv() -> None:
    edge_index = random_graph(seed=12)
    graph = AttentionGraph.from_edge_index(edge_index, 60)
    assert graph.num_edges == (edge_index[0] != edge_index[1]).sum() + 60
    reference, _ = pair_of_layers(4, 3, 2, concat=True)
    x = torch.randn(60, 4)
    torch.testing.assert_close(reference(x, graph.edge_index), reference(x, edge_index),
                               **TOLERANCE)
    assert graph.layout(2) is graph.layout(2)  # built once per head count


def test_only_self_loops_and_bad_indices() -> None:
    reference, layer = pair_of_layers(3, 2, 4, concat=True)
    x = torch.randn(5, 3)
    empty = torch.zeros(2, 0, dtype=torch.long)
    torch.testing.assert_close(layer(x, empty), reference(x, empty), **TOLERANCE)
    with pytest.raises(ValueError, match="outside"):
        AttentionGraph.from_edge_index(torch.tensor([[0], [5]]), 5)
    with pytest.raises(ValueError, match="nodes"):
        layer(torch.randn(4, 3), AttentionGraph.from_edge_index(empty, 5))
