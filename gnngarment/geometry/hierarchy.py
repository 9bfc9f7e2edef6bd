"""A garment's multilevel pooling hierarchy: Algorithm 1 applied repeatedly, with the
Algorithm 2 unpooling matrix of every step, computed once per topology and cached."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from gnngarment.geometry.pooling import pool
from gnngarment.geometry.unpooling import unpooling_matrix
from gnngarment.io.npz import load_npz, save_npz_atomic

#: Bumped whenever the file layout or the algorithm changes, so stale caches rebuild.
HIERARCHY_FORMAT_VERSION = 1


@dataclass
class PoolLevel:
    """One pooling step from level ``k`` (fine) to level ``k + 1`` (coarse).

    Attributes:
        kept: ``(N_{k+1},)`` ascending indices into level ``k`` of the kept vertices.
        edge_index: ``(2, E_{k+1})`` coarse edge index (level ``k + 1`` numbering).
        unpool: ``(N_k, N_{k+1})`` CSR unpooling matrix (rows sum to 1).
        centres: ``(C,)`` level-``k`` index of each component's BFS centre.
    """

    kept: np.ndarray
    edge_index: np.ndarray
    unpool: sp.csr_matrix
    centres: np.ndarray

    @property
    def num_vertices(self) -> int:
        """Vertex count of the coarse level this step produces."""
        return len(self.kept)


@dataclass
class PoolHierarchy:
    """Level 0 (the mesh's edge graph) plus ``len(levels)`` pooling steps.

    Attributes:
        num_vertices: ``N_0``, vertices of the mesh.
        edge_index: ``(2, E_0)`` edge index of the mesh.
        levels: pooling steps; ``levels[k]`` maps level ``k`` to ``k + 1``.
    """

    num_vertices: int
    edge_index: np.ndarray
    levels: list[PoolLevel] = field(default_factory=list)

    @property
    def depth(self) -> int:
        return len(self.levels)

    def vertex_counts(self) -> list[int]:
        """Vertex count of every level, finest first."""
        return [self.num_vertices] + [level.num_vertices for level in self.levels]

    def edge_counts(self) -> list[int]:
        """Undirected edge count of every level, finest first."""
        return [self.edge_index.shape[1] // 2] + [
            level.edge_index.shape[1] // 2 for level in self.levels]

    def save(self, path: str | Path) -> None:
        """Write to one ``.npz`` atomically (temp file in the same folder, then rename),
        so an interrupted write never leaves a truncated cache behind."""
        path = Path(path)
        arrays: dict[str, np.ndarray] = {
            "format_version": np.array(HIERARCHY_FORMAT_VERSION),
            "num_vertices": np.array(self.num_vertices),
            "depth": np.array(self.depth),
            "edge_index": self.edge_index,
        }
        for k, level in enumerate(self.levels):
            unpool = level.unpool.tocsr()
            arrays |= {
                f"level{k}_kept": level.kept,
                f"level{k}_edge_index": level.edge_index,
                f"level{k}_centres": level.centres,
                f"level{k}_unpool_data": unpool.data,
                f"level{k}_unpool_indices": unpool.indices,
                f"level{k}_unpool_indptr": unpool.indptr,
                f"level{k}_unpool_shape": np.array(unpool.shape),
            }
        save_npz_atomic(path, arrays)

    @classmethod
    def load(cls, path: str | Path) -> PoolHierarchy:
        """Read a hierarchy written by :meth:`save`.

        Raises:
            ValueError: missing, truncated or corrupt file, or another format version;
                the message names the file.
        """
        path = Path(path)
        data = load_npz(path, required=("format_version", "num_vertices", "depth",
                                        "edge_index"))
        version = int(data["format_version"])
        if version != HIERARCHY_FORMAT_VERSION:
            raise ValueError(f"{path}: hierarchy format version {version}, expected "
                             f"{HIERARCHY_FORMAT_VERSION}; rebuild it")
        try:
            levels = []
            for k in range(int(data["depth"])):
                shape = tuple(int(s) for s in data[f"level{k}_unpool_shape"])
                unpool = sp.csr_matrix((data[f"level{k}_unpool_data"],
                                        data[f"level{k}_unpool_indices"],
                                        data[f"level{k}_unpool_indptr"]), shape=shape)
                levels.append(PoolLevel(kept=data[f"level{k}_kept"],
                                        edge_index=data[f"level{k}_edge_index"],
                                        unpool=unpool, centres=data[f"level{k}_centres"]))
        except (KeyError, ValueError) as error:
            raise ValueError(f"{path}: corrupt hierarchy file ({error})") from error
        return cls(num_vertices=int(data["num_vertices"]), edge_index=data["edge_index"],
                   levels=levels)


def pool_hierarchy(edge_index: np.ndarray, num_vertices: int, depth: int) -> PoolHierarchy:
    """Pool ``depth`` times; level ``k + 1`` is pooled from level ``k``'s coarse graph
    (with the edges pooling added), not from the mesh.

    Shapes:
        edge_index: ``(2, E)`` symmetric edge index of the mesh (level 0).
    """
    if depth < 0:
        raise ValueError(f"depth must be >= 0, got {depth}")
    edge_index = np.asarray(edge_index, dtype=np.int64)
    hierarchy = PoolHierarchy(num_vertices=num_vertices, edge_index=edge_index)
    current_edges, current_count = edge_index, num_vertices
    for _ in range(depth):
        pooled = pool(current_edges, current_count)
        unpool = unpooling_matrix(current_edges, current_count, pooled.kept)
        hierarchy.levels.append(PoolLevel(kept=pooled.kept, edge_index=pooled.edge_index,
                                          unpool=unpool, centres=pooled.centres))
        current_edges, current_count = pooled.edge_index, len(pooled.kept)
    return hierarchy
