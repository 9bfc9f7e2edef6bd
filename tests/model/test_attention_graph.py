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


def test_repeated_copies_equal_the_offset_edge_list() -> None:
    # The frames of a garment: copies of one graph numbered copy by copy. The repeated
    # build must give exactly the structure of the stacked edge list, and know its blocks.
    first, second = random_graph(seed=1), random_graph(seed=2, num_nodes=30, connected=20,
                                                          edges=80)
    blocks = [(AttentionGraph.from_edge_index(first, 60), 3),
              (AttentionGraph.from_edge_index(second, 30), 2)]
    offsets = [0, 60, 120, 180, 210]
    stacked = torch.cat([first + offsets[c] for c in range(3)]
                        + [second + offsets[3 + c] for c in range(2)], dim=1)
    expected = AttentionGraph.from_edge_index(stacked, 240)
    repeated = AttentionGraph.repeated(blocks)
    assert repeated.num_nodes == 240
    assert torch.equal(repeated.ptr, expected.ptr)
    assert torch.equal(repeated.source, expected.source)
    assert repeated.blocks is not None and [c for _, c in repeated.blocks] == [3, 2]
    layouts = repeated.block_layouts(4)
    assert layouts is not None and layouts[0][0] is blocks[0][0].layout(4)
    assert expected.block_layouts(4) is None


@pytest.mark.parametrize("heads", [1, 4])
def test_assembled_layout_and_transposes_equal_the_built_ones(heads: int) -> None:
    # A repeated graph assembles its layout and its patterns' transposes from its
    # blocks' (no sort); they must be the very index arrays a plain build gives.
    first, second = random_graph(seed=1), random_graph(seed=2, num_nodes=30, connected=20,
                                                          edges=80)
    repeated = AttentionGraph.repeated([(AttentionGraph.from_edge_index(first, 60), 3),
                                        (AttentionGraph.from_edge_index(second, 30), 2)])
    plain = AttentionGraph.from_edge_index(repeated.edge_index, repeated.num_nodes)
    assembled, built = repeated.layout(heads), plain.layout(heads)
    for name in ("source_slot", "target_slot", "segment_index", "segment_ptr"):
        assert torch.equal(getattr(assembled, name), getattr(built, name)), name
    for name in ("head_rows", "node_rows"):
        a, b = getattr(assembled, name), getattr(built, name)
        assert a.blocks is not None and b.blocks is None
        assert torch.equal(a.crow, b.crow) and torch.equal(a.col, b.col) and a.shape == b.shape
        for x, y in zip(a.transpose_structure(), b.transpose_structure(), strict=True):
            assert torch.equal(x, y), name
