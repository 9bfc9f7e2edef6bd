"""The influence field of a target: how far from it the attribution mass lies.

The paper (Sec. 4.1, Fig. 3) shows the field as a picture; we measure it. For a heat
``h_i >= 0`` over the vertices and a target (a vertex or a set), the field at mass
``q`` (0.9 by default) is described three ways:

* ``count``: the fewest vertices that hold a fraction ``q`` of ``Σh`` (the area of the
  hottest part, wherever it is);
* ``radius``: the smallest geodesic ball around the target holding ``q`` of ``Σh``
  (metres, edge-path geodesics as :func:`geodesic_distances`);
* ``hops``: the same ball measured in mesh edges, which is what the receptive field
  of a stack of GAT layers is counted in;
* ``support`` and ``support_hops``: the vertices with any heat (above ``floor`` × the
  peak) and the farthest of them in hops. With ``floor = 0`` this is the receptive
  field itself: outside it the gradient is exactly zero (no path in the graph), so
  the numbers are structural and free of round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import shortest_path

from gnngarment.geometry.geodesics import geodesic_distances


@dataclass
class InfluenceField:
    """Extent of the attribution mass around a target.

    Attributes:
        mass: the fraction ``q`` of the total heat the numbers refer to.
        count: fewest vertices holding ``q`` of the heat.
        radius: geodesic radius (metres) of the smallest ball around the target holding
            ``q`` of the heat (``inf`` if mass lies in another connected component).
        hops: the same in mesh edges (``-1`` if it needs another component).
        support: vertices with heat above ``floor`` × the peak.
        support_hops: hops from the target to the farthest of them (``-1`` if one is
            in another component).
        total: ``Σh``.
    """

    mass: float
    count: int
    radius: float
    hops: int
    support: int
    support_hops: int
    total: float


def hop_distances(edge_index: np.ndarray, num_vertices: int, sources: np.ndarray) -> np.ndarray:
    """``(N,)`` fewest mesh edges from the nearest source to every vertex (``inf`` where
    unreachable).

    Shapes:
        edge_index ``(2, E)``, sources ``(K,)`` → ``(N,)`` float64.
    """
    edge_index = np.asarray(edge_index)
    graph = sp.coo_matrix((np.ones(edge_index.shape[1]), (edge_index[0], edge_index[1])),
                          shape=(num_vertices, num_vertices)).tocsr()
    distances = shortest_path(graph, directed=False, unweighted=True,
                              indices=np.asarray(sources, dtype=np.int64))
    return np.atleast_2d(distances).min(axis=0)


def influence_field(heat: np.ndarray, pos: np.ndarray, edge_index: np.ndarray,
                    sources: int | np.ndarray, mass: float = 0.9,
                    floor: float = 0.0) -> InfluenceField:
    """Measure the influence field of ``sources`` in ``heat``.

    Args:
        heat: ``(N,)`` non-negative per-vertex attribution (:meth:`Attribution.heat`).
        pos: ``(N, 3)`` rest positions (metres).
        edge_index: ``(2, E)`` mesh edges (``PoolHierarchy.edge_index``).
        sources: the target vertex or ``(K,)`` target vertices (distance = to the nearest).
        mass: fraction of the total heat, in ``(0, 1]``.
        floor: heat at or below ``floor`` × the peak is outside the support.

    Raises:
        ValueError: wrong shapes, negative or all-zero heat, ``mass`` out of range,
            source out of range.
    """
    heat = np.asarray(heat, dtype=np.float64)
    n = heat.shape[0]
    if heat.ndim != 1:
        raise ValueError(f"heat must have shape (N,), got {heat.shape}")
    if np.asarray(pos).shape != (n, 3):
        raise ValueError(f"pos must have shape ({n}, 3), got {np.asarray(pos).shape}")
    if not 0.0 < mass <= 1.0:
        raise ValueError(f"mass must be in (0, 1], got {mass}")
    if not 0.0 <= floor < 1.0:
        raise ValueError(f"floor must be in [0, 1), got {floor}")
    if not np.isfinite(heat).all() or (heat < 0).any():
        raise ValueError("heat must be finite and non-negative")
    total = float(heat.sum())
    if total <= 0.0:
        raise ValueError("heat is zero everywhere: nothing to measure")
    sources = np.atleast_1d(np.asarray(sources, dtype=np.int64))
    if sources.size == 0 or sources.min() < 0 or sources.max() >= n:
        raise ValueError(f"sources must be vertex indices in 0..{n - 1}, got {sources.tolist()}")
    # Relative slack so that float round-off in the cumulative sum cannot push the
    # threshold past the last vertex that is really needed.
    needed = mass * total * (1.0 - 1e-12)

    count = int(np.searchsorted(np.cumsum(np.sort(heat)[::-1]), needed) + 1)
    radius = _ball_radius(heat, geodesic_distances(pos, edge_index, sources).min(axis=0),
                          needed)
    hops = hop_distances(edge_index, n, sources)
    hop_radius = _ball_radius(heat, hops, needed)
    inside = heat > floor * heat.max()
    farthest = hops[inside].max()
    return InfluenceField(mass=mass, count=min(count, n), radius=radius,
                          hops=_finite_int(hop_radius), support=int(inside.sum()),
                          support_hops=_finite_int(farthest), total=total)


def mass_profile(heat: np.ndarray, distances: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """``(R,)`` fraction of ``Σheat`` within each of ``radii`` of the target, for
    distances ``(N,)`` from it (hops or metres)."""
    heat = np.asarray(heat, dtype=np.float64)
    order = np.argsort(distances, kind="stable")
    cumulative = np.cumsum(heat[order]) / heat.sum()
    reach = np.searchsorted(np.asarray(distances)[order], np.asarray(radii), side="right")
    return np.where(reach > 0, cumulative[np.maximum(reach - 1, 0)], 0.0)


def _finite_int(value: float) -> int:
    return int(value) if np.isfinite(value) else -1


def _ball_radius(heat: np.ndarray, distances: np.ndarray, needed: float) -> float:
    """Smallest ``r`` with ``Σ_{d_i <= r} h_i >= needed``."""
    order = np.argsort(distances, kind="stable")
    cumulative = np.cumsum(heat[order])
    position = min(int(np.searchsorted(cumulative, needed)), len(order) - 1)
    return float(distances[order[position]])
