"""E^gg (:class:`GarmentGraphEncoder`): joint-specific GAT heads modulated by the style."""

from __future__ import annotations

import numpy as np
import torch

from gnngarment.data.vertex_features import VERTEX_FEATURE_CHANNELS
from gnngarment.geometry import edge_index_from_faces
from gnngarment.model.garment_encoder import GarmentGraphEncoder
from tests.meshes import interleave, random_disk, tube

CHANNELS = [8, 16, 16]  # three blocks; the style multiplies the second block's output
HEADS = 24


def encoder(seed: int = 0) -> GarmentGraphEncoder:
    torch.manual_seed(seed)
    return GarmentGraphEncoder(VERTEX_FEATURE_CHANNELS, CHANNELS, HEADS).eval()


def inputs(n: int, seed: int = 0) -> tuple[torch.Tensor, torch.Tensor]:
    generator = torch.Generator().manual_seed(seed)
    return (torch.randn(n, VERTEX_FEATURE_CHANNELS, generator=generator),
            torch.rand(n, CHANNELS[-2], generator=generator) + 0.5)


def edges(faces: np.ndarray, n: int) -> torch.Tensor:
    return torch.from_numpy(edge_index_from_faces(faces, n))


def path(n: int) -> torch.Tensor:
    """Edge index of the path 0 - 1 - ... - n-1 (graph distance = index difference)."""
    a = torch.arange(n - 1)
    return torch.stack([torch.cat([a, a + 1]), torch.cat([a + 1, a])])


def close(actual: torch.Tensor, expected: torch.Tensor) -> None:
    np.testing.assert_allclose(actual.detach().numpy(), expected.detach().numpy(),
                               rtol=1e-5, atol=1e-6)


def changed_rows(a: torch.Tensor, b: torch.Tensor) -> list[int]:
    return torch.nonzero((a - b).abs().flatten(1).amax(1) > 1e-6).flatten().tolist()


def test_features_are_split_by_joint_at_the_last_width() -> None:
    pos, faces = tube(4, 6)
    x, style = inputs(len(pos))
    out = encoder()(x, edges(faces, len(pos)), style)
    assert out.shape == (len(pos), HEADS, CHANNELS[-1])  # (N, S, F)
    assert (out >= 0).all() and (out > 0).any()  # ReLU


def test_relabelling_vertices_permutes_the_output() -> None:
    pos, faces = random_disk(60, 3)
    n = len(pos)
    x, style = inputs(n)
    model = encoder()
    out = model(x, edges(faces, n), style)
    permutation = torch.from_numpy(np.random.default_rng(5).permutation(n))
    _, relabelled_faces = interleave(pos, faces, seed=5)
    moved = model(x[permutation], edges(relabelled_faces, n), style[permutation])
    close(moved, out[permutation])


def test_a_vertex_sees_as_many_rings_as_there_are_blocks() -> None:
    n = 9
    x, style = inputs(n)
    model = encoder()
    out = model(x, path(n), style)
    other = x.clone()
    other[0] += 2.0
    # Three GAT blocks: vertex 0's features reach vertices 0..3 and no further.
    assert changed_rows(model(other, path(n), style), out) == [0, 1, 2, 3]


def test_the_style_enters_before_the_last_block_only() -> None:
    n = 9
    x, style = inputs(n)
    model = encoder()
    out = model(x, path(n), style)
    other = style.clone()
    other[4] *= 3.0
    # One block after the modulation: vertex 4's style reaches its ring 3..5 only.
    assert changed_rows(model(x, path(n), other), out) == [3, 4, 5]


def test_without_style_every_vertex_gets_the_last_blocks_bias() -> None:
    pos, faces = tube(4, 6)
    n = len(pos)
    x, style = inputs(n)
    model = encoder()
    with torch.no_grad():
        model.blocks[-1].bias.normal_()
    out = model(x, edges(faces, n), torch.zeros_like(style))
    expected = torch.relu(model.blocks[-1].bias).view(HEADS, -1).expand(n, -1, -1)
    close(out, expected)


def test_garments_in_one_graph_do_not_mix() -> None:
    disk, skirt = random_disk(40, 1), tube(4, 6)
    sizes = [len(disk[0]), len(skirt[0])]
    x, style = inputs(sum(sizes))
    model = encoder()
    together = model(x, torch.cat([edges(disk[1], sizes[0]),
                                   edges(skirt[1], sizes[1]) + sizes[0]], dim=1), style)
    alone = model(x[sizes[0]:], edges(skirt[1], sizes[1]), style[sizes[0]:])
    close(together[sizes[0]:], alone)
