from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from gnngarment.geometry.graph import connected_components, edge_index_from_faces
from gnngarment.geometry.hierarchy import PoolHierarchy, pool_hierarchy
from gnngarment.geometry.pooling import pool
from tests.meshes import random_disk, tube, union


@pytest.fixture
def two_piece() -> tuple[np.ndarray, np.ndarray]:
    return union(random_disk(300, 4), tube(8, 12))


def test_each_level_is_pooled_from_the_previous_coarse_graph(two_piece) -> None:
    pos, faces = two_piece
    edge_index = edge_index_from_faces(faces, len(pos))
    hierarchy = pool_hierarchy(edge_index, len(pos), depth=3)

    current_edges, current_count = edge_index, len(pos)
    for level in hierarchy.levels:
        expected = pool(current_edges, current_count)
        np.testing.assert_array_equal(level.kept, expected.kept)
        np.testing.assert_array_equal(level.edge_index, expected.edge_index)
        assert level.unpool.shape == (current_count, len(level.kept))
        current_edges, current_count = level.edge_index, len(level.kept)
    counts = hierarchy.vertex_counts()
    assert all(a > b for a, b in itertools.pairwise(counts))
    assert len(hierarchy.edge_counts()) == 4


def test_components_survive_every_level(two_piece) -> None:
    pos, faces = two_piece
    hierarchy = pool_hierarchy(edge_index_from_faces(faces, len(pos)), len(pos), depth=3)
    for level in hierarchy.levels:
        assert connected_components(level.edge_index, level.num_vertices).max() == 1


def test_composed_unpooling_reproduces_a_constant_field(two_piece) -> None:
    pos, faces = two_piece
    hierarchy = pool_hierarchy(edge_index_from_faces(faces, len(pos)), len(pos), depth=2)
    field = np.full((hierarchy.levels[-1].num_vertices, 4), -0.7)
    for level in reversed(hierarchy.levels):
        field = level.unpool @ field
    assert field.shape == (len(pos), 4)
    np.testing.assert_allclose(field, -0.7, atol=1e-12)


def test_save_load_round_trip(two_piece, tmp_path: Path) -> None:
    pos, faces = two_piece
    hierarchy = pool_hierarchy(edge_index_from_faces(faces, len(pos)), len(pos), depth=2)
    path = tmp_path / "sub" / "garment.hierarchy.npz"
    hierarchy.save(path)
    loaded = PoolHierarchy.load(path)
    assert loaded.vertex_counts() == hierarchy.vertex_counts()
    np.testing.assert_array_equal(loaded.edge_index, hierarchy.edge_index)
    for a, b in zip(loaded.levels, hierarchy.levels, strict=True):
        np.testing.assert_array_equal(a.kept, b.kept)
        np.testing.assert_array_equal(a.edge_index, b.edge_index)
        np.testing.assert_array_equal(a.centres, b.centres)
        assert (a.unpool != b.unpool).nnz == 0
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temp file left


def test_depth_zero_has_only_the_mesh_level(two_piece) -> None:
    pos, faces = two_piece
    hierarchy = pool_hierarchy(edge_index_from_faces(faces, len(pos)), len(pos), depth=0)
    assert hierarchy.vertex_counts() == [len(pos)]
    with pytest.raises(ValueError, match="depth"):
        pool_hierarchy(hierarchy.edge_index, len(pos), depth=-1)


def test_truncated_and_missing_files_are_named(two_piece, tmp_path: Path) -> None:
    pos, faces = two_piece
    path = tmp_path / "h.npz"
    pool_hierarchy(edge_index_from_faces(faces, len(pos)), len(pos), depth=1).save(path)
    data = path.read_bytes()
    truncated = tmp_path / "truncated.npz"
    truncated.write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="truncated.npz"):
        PoolHierarchy.load(truncated)
    with pytest.raises(ValueError, match="absent.npz: file not found"):
        PoolHierarchy.load(tmp_path / "absent.npz")


def test_interrupted_save_keeps_the_previous_file(two_piece, tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    pos, faces = two_piece
    path = tmp_path / "h.npz"
    hierarchy = pool_hierarchy(edge_index_from_faces(faces, len(pos)), len(pos), depth=1)
    hierarchy.save(path)
    before = path.read_bytes()

    def explode(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez", explode)
    with pytest.raises(KeyboardInterrupt):
        hierarchy.save(path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["h.npz"]
