"""GraphLevels' cached attention graphs and unpooling operators."""

from __future__ import annotations

import torch

from gnngarment.geometry import edge_index_from_faces, pool_hierarchy
from gnngarment.model import MultilevelProcessor, stack_hierarchies
from tests.meshes import tube


def test_structures_cached_during_inference_serve_training() -> None:
    # A context prepared for inference may later be trained on: its cached structures
    # must not be inference tensors (autograd refuses to save those).
    hierarchy = pool_hierarchy(edge_index_from_faces(tube(6, 9)[1], 54), 54, 2)
    graph = stack_hierarchies([hierarchy] * 2, depth=2)
    torch.manual_seed(0)
    processor = MultilevelProcessor(4, 8, 2, 3, 2, 2)
    x = torch.randn(108, 4)
    with torch.inference_mode():
        before = processor(x, graph)
    x.requires_grad_(True)
    after = processor(x, graph)
    after.sum().backward()
    torch.testing.assert_close(after.detach(), before, rtol=0, atol=1e-6)
    assert x.grad is not None and x.grad.abs().sum() > 0


def test_graph_levels_rebuild_a_replaced_level() -> None:
    hierarchy = pool_hierarchy(edge_index_from_faces(tube(6, 9)[1], 54), 54, 1)
    graph = stack_hierarchies([hierarchy], depth=1)
    first = graph.attention_graph(0)
    graph.edge_index[0] = graph.edge_index[0].clone()
    assert graph.attention_graph(0) is not first


def test_frames_of_one_garment_are_built_as_repeated_copies() -> None:
    # Consecutive copies of one hierarchy (a garment's frames) form a run; every level's
    # attention graph then knows its blocks and is the plain stacked graph.
    from gnngarment.model.attention_graph import AttentionGraph

    first = pool_hierarchy(edge_index_from_faces(tube(6, 9)[1], 54), 54, 2)
    second = pool_hierarchy(edge_index_from_faces(tube(5, 8)[1], 40), 40, 2)
    graph = stack_hierarchies([first, first, first, second, first], depth=2)
    assert [(h is first, copies) for h, copies in graph.runs] == [(True, 3), (False, 1),
                                                                  (True, 1)]
    for level in range(3):
        repeated = graph.attention_graph(level)
        plain = AttentionGraph.from_edge_index(graph.edge_index[level],
                                               int(graph.batch[level].shape[0]))
        assert repeated.blocks is not None
        assert [copies for _, copies in repeated.blocks] == [3, 1, 1]
        assert torch.equal(repeated.ptr, plain.ptr)
        assert torch.equal(repeated.source, plain.source)
