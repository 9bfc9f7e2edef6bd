from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import torch

from gnngarment.geometry import edge_index_from_faces, pool_hierarchy
from gnngarment.model import MultilevelProcessor, stack_hierarchies
from tests.meshes import random_disk, tube


def hierarchies():
    meshes = [random_disk(120, 2), tube(6, 9)]
    return [pool_hierarchy(edge_index_from_faces(f, len(p)), len(p), 2) for p, f in meshes]


def test_stacked_levels_are_block_diagonal_copies() -> None:
    a, b = hierarchies()
    graph = stack_hierarchies([a, b, a], depth=2)
    counts = [a.vertex_counts(), b.vertex_counts()]
    for level in range(3):
        n = [counts[0][level], counts[1][level], counts[0][level]]
        assert graph.batch[level].tolist() == [0] * n[0] + [1] * n[1] + [2] * n[2]
        edges = graph.edge_index[level]
        # No edge crosses graphs.
        assert (graph.batch[level][edges[0]] == graph.batch[level][edges[1]]).all()
    unpool = graph.unpool[0].to_dense().numpy()
    expected = sp.block_diag([a.levels[0].unpool, b.levels[0].unpool, a.levels[0].unpool])
    np.testing.assert_allclose(unpool, expected.toarray(), atol=1e-7)
    assert graph.kept[1].max() < sum(c[1] for c in (counts[0], counts[1], counts[0]))


def test_unpooling_in_the_processor_reproduces_constants() -> None:
    graph = stack_hierarchies(hierarchies(), depth=2)
    coarse = torch.full((graph.kept[1].shape[0], 5), 2.5)
    fine = torch.sparse.mm(graph.unpool[0], torch.sparse.mm(graph.unpool[1], coarse))
    torch.testing.assert_close(fine, torch.full((graph.batch[0].shape[0], 5), 2.5))


def test_multilevel_reaches_farther_than_single_level() -> None:
    # A perturbation at one vertex changes outputs farther away with pooling: the
    # receptive field grows with the levels (the blueprint's motivation, Fig. 3).
    hierarchy = pool_hierarchy(edge_index_from_faces(tube(30, 8)[1], 240), 240, 3)
    graph = stack_hierarchies([hierarchy], depth=3)
    reach = {}
    for levels in (0, 3):
        torch.manual_seed(0)
        processor = MultilevelProcessor(4, 8, 2, 3, 2, levels)
        x = torch.randn(240, 4, requires_grad=True)
        processor(x, graph)[0].sum().backward()
        reach[levels] = int((x.grad.abs().sum(1) > 0).sum())
    assert reach[3] > 2 * reach[0]
