"""Garments worn together: which lies outside which, and keeping them apart.

An outfit's garments overlap where one is worn over the other (a T-shirt's hem over the
trousers' waistband). Garments are open surfaces with no inside, so "outside" is read
along the **outward** normal of the garment beneath: each garment's winding is first
turned to face away from the body (:func:`outward_faces`), then a point's *height* over
a garment is its offset from the closest surface point along that face's normal
(:func:`~gnngarment.geometry.signed_distance.side_offsets`, an exact BVH query on the
garment mesh, refit per frame as the body resolution does). Points whose offset is not
along the normal (alignment below :attr:`LayerSettings.alignment`: level with a hem,
beyond the surface's edge) are not over that garment at all.

* :func:`layer_order` — at rest, for every pair of garments, the share of the vertices
  where they overlap that lie on each one's outer side; a pair whose evidence is split
  (neither share above :attr:`LayerSettings.decisive`) or an order with a cycle raises
  :class:`LayerOrderError` instead of guessing.
* :func:`resolve_layer_collisions` — every frame, the vertices of an outer garment behind
  (or closer than the clearance to) a garment beneath are pushed out along its normal,
  the push spread over the outer garment's edge graph as the body resolution spreads its
  own (:class:`~gnngarment.geometry.body_collisions.PushGraph`), then re-checked.
* :func:`layer_penetration` — the share of an outer garment's vertices behind the one
  beneath (the metric ``evaluate`` and ``animate`` report).

Pure numpy/scipy with Warp's mesh queries; no torch.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from gnngarment.geometry.body_collisions import PushGraph

#: Relative slack on the clearance when checking the result (float32 queries).
_ACCEPT = 1e-3


@dataclass
class LayerSettings:
    """Settings of the layer order and the layer resolution (mirrors ``configs/layers.yaml``).

    Attributes:
        clearance: every outer-garment vertex over a garment beneath ends at least this
            far outside it [m].
        search_band: closest points on the garment beneath are searched this far [m]; a
            vertex deeper behind it than this is not seen.
        alignment: a vertex counts as over a garment when its offset from the closest
            point is at least this much along that face's normal (|cos|, 0..1).
        overlap: at rest, vertices within this distance of the other garment are where
            two garments overlap [m].
        decisive: share of the overlapping vertices that must agree on which garment is
            outside (0.5..1); below it the order is ambiguous.
        min_overlap: fewer overlapping vertices than this: the two garments do not
            overlap and need no order.
        smoothing_radius: path length along the outer garment's edges over which a push
            falls off to zero [m].
        smoothing_iterations: Jacobi passes over the spread pushes.
        passes: re-check / project-out rounds after the spread.
    """

    clearance: float = 0.003
    search_band: float = 0.03
    alignment: float = 0.5
    overlap: float = 0.03
    decisive: float = 0.8
    min_overlap: int = 20
    smoothing_radius: float = 0.05
    smoothing_iterations: int = 4
    passes: int = 3

    def __post_init__(self) -> None:
        for name in ("clearance", "search_band", "overlap", "smoothing_radius"):
            if not 0 <= getattr(self, name) <= 1:
                raise ValueError(f"{name} must be in [0, 1] m, got {getattr(self, name)}")
        if not 0 <= self.alignment <= 1:
            raise ValueError(f"alignment must be in [0, 1], got {self.alignment}")
        if not 0.5 < self.decisive <= 1:
            raise ValueError(f"decisive must be in (0.5, 1], got {self.decisive}")
        for name in ("min_overlap", "smoothing_iterations", "passes"):
            if not 0 <= getattr(self, name) <= 1000:
                raise ValueError(f"{name} must be in 0..1000, got {getattr(self, name)}")


class LayerOrderError(ValueError):
    """The garments' order cannot be told (a split pair or a cycle); the message names
    the garments and says how to give the order."""


@dataclass
class LayerRelation:
    """What the rest pose says about two garments ``outer`` and ``inner`` (indices).

    Attributes:
        overlap: vertices of either within :attr:`LayerSettings.overlap` of the other.
        agreement: share of those that put ``outer`` outside ``inner`` (≥ 0.5).
    """

    outer: int
    inner: int
    overlap: int
    agreement: float


@dataclass
class LayerStats:
    """What :func:`resolve_layer_collisions` did, per frame ``(T,)``.

    Attributes:
        through: outer-garment vertices behind a garment beneath before.
        close: vertices behind or closer than the clearance before.
        moved: vertices moved (those and their neighbours).
        max_push: largest vertex displacement [m].
        remaining: vertices still behind or closer than the clearance after.
    """

    through: np.ndarray
    close: np.ndarray
    moved: np.ndarray
    max_push: np.ndarray
    remaining: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


def connected_parts(faces: np.ndarray, num_vertices: int) -> list[np.ndarray]:
    """The vertex indices ``(N_k,)`` of each connected component of a mesh (joined by
    its triangles), ordered by their first vertex; vertices in no triangle belong to none.
    A file holding a top and a bottom as two components splits into two garments."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    faces = np.asarray(faces, dtype=np.int64)
    rows = np.repeat(faces[:, 0], 2)
    cols = faces[:, 1:].ravel()
    graph = sp.csr_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)),
                          shape=(num_vertices, num_vertices))
    _, labels = connected_components(graph, directed=False)
    used = np.zeros(num_vertices, dtype=bool)
    used[faces.ravel()] = True
    parts: dict[int, list[int]] = {}
    for vertex in np.flatnonzero(used):
        parts.setdefault(int(labels[vertex]), []).append(int(vertex))
    return [np.asarray(part, dtype=np.int64) for part in parts.values()]


def part_mesh(pos: np.ndarray, faces: np.ndarray, part: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """The sub-mesh ``(pos (N_k, 3), faces (F_k, 3))`` of the vertices ``part`` (one of
    :func:`connected_parts`), its faces renumbered."""
    index = np.full(len(pos), -1, dtype=np.int64)
    index[part] = np.arange(len(part))
    faces = np.asarray(faces, dtype=np.int64)
    keep = (index[faces] >= 0).all(axis=1)
    return np.asarray(pos)[part], index[faces[keep]]


def _face_normals(pos: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    corner = np.asarray(pos, dtype=np.float64)[faces]
    cross = np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0])
    return cross, corner.mean(axis=1)


def outward_faces(pos: np.ndarray, faces: np.ndarray, body_vertices: np.ndarray,
                  body_faces: np.ndarray) -> np.ndarray:
    """``faces (F, 3)`` wound so that the garment's normals point away from the body:
    flipped when, weighted by area, most faces' normals point towards the body's closest
    surface point. The garment is at rest on the body (``pos (N, 3)``, body
    ``(N_b, 3)``/``(F_b, 3)``, metres)."""
    from gnngarment.geometry.signed_distance import SEARCH_RADIUS, surface_offsets, warp_mesh

    faces = np.asarray(faces, dtype=np.int64)
    cross, centre = _face_normals(pos, faces)
    _, closest, _ = surface_offsets(warp_mesh(body_vertices, body_faces), centre,
                                    SEARCH_RADIUS)
    away = np.einsum("fa,fa->f", cross, centre - closest)
    return faces if away.sum() >= 0 else faces[:, ::-1].copy()


def _garment_mesh(pos: np.ndarray, faces: np.ndarray):
    from gnngarment.geometry.signed_distance import warp_mesh

    return warp_mesh(pos, faces)


def _heights(mesh, points: np.ndarray, band: float, alignment: float
             ) -> tuple[np.ndarray, np.ndarray]:
    """Height ``(N,)`` of ``points`` over the garment ``mesh`` (``inf`` where the point is
    not over it within ``band``) and the normal ``(N, 3)``."""
    from gnngarment.geometry.signed_distance import side_offsets

    height, normal, aligned = side_offsets(mesh, points, band)
    over = np.isfinite(height) & (aligned >= alignment) & (np.abs(height) <= band)
    return np.where(over, height, np.inf), normal


def layer_relations(garments: Sequence[tuple[np.ndarray, np.ndarray]],
                    settings: LayerSettings | None = None) -> list[LayerRelation]:
    """Every pair of garments that overlaps at rest, with which lies outside.

    Args:
        garments: ``(pos (N_k, 3), faces (F_k, 3))`` per garment, at rest on one body,
            faces wound outward (:func:`outward_faces`), metres.
        settings: thresholds; default :class:`LayerSettings`.

    Returns:
        One :class:`LayerRelation` per overlapping pair (``agreement`` may be below
        :attr:`LayerSettings.decisive`: :func:`layer_order` refuses those).
    """
    settings = settings or LayerSettings()
    meshes = [_garment_mesh(pos, faces) for pos, faces in garments]
    relations = []
    for a in range(len(garments)):
        for b in range(a + 1, len(garments)):
            # a's vertices over b (height > 0: a outside) and b's over a (< 0: a outside).
            over_b, _ = _heights(meshes[b], garments[a][0], settings.overlap,
                                 settings.alignment)
            over_a, _ = _heights(meshes[a], garments[b][0], settings.overlap,
                                 settings.alignment)
            over_b, over_a = over_b[np.isfinite(over_b)], over_a[np.isfinite(over_a)]
            count = len(over_b) + len(over_a)
            if count < max(settings.min_overlap, 1):
                continue
            a_outside = (float((over_b > 0).sum()) + float((over_a < 0).sum())) / count
            if a_outside >= 0.5:
                relations.append(LayerRelation(a, b, count, a_outside))
            else:
                relations.append(LayerRelation(b, a, count, 1.0 - a_outside))
    return relations


def layer_order(garments: Sequence[tuple[np.ndarray, np.ndarray]], names: Sequence[str],
                settings: LayerSettings | None = None, given: Sequence[str] | None = None
                ) -> tuple[list[int], list[LayerRelation]]:
    """The garments from innermost to outermost.

    Args:
        garments: as :func:`layer_relations`.
        names: one per garment (for messages and ``given``).
        settings: thresholds; default :class:`LayerSettings`.
        given: the order, innermost first, by name (every garment once): used as it is,
            after checking it names every garment.

    Returns:
        The order (indices, innermost first; garments that overlap none keep their
        place) and the measured relations.

    Raises:
        LayerOrderError: a pair whose overlap does not say which is outside, or a cycle
            (a crossing order); ``given`` that is not a permutation of ``names``.
    """
    import networkx as nx

    settings = settings or LayerSettings()
    names = list(names)
    relations = layer_relations(garments, settings)
    if given is not None:
        given = list(given)
        if sorted(given) != sorted(names) or len(set(given)) != len(given):
            raise LayerOrderError(f"--layers {','.join(given)}: must name every garment "
                                  f"once ({', '.join(names)})")
        return [names.index(name) for name in given], relations
    graph = nx.DiGraph()
    graph.add_nodes_from(range(len(garments)))
    for relation in relations:
        if relation.agreement < settings.decisive:
            raise LayerOrderError(
                f"{names[relation.outer]} and {names[relation.inner]}: where they overlap "
                f"({relation.overlap} vertices) only {100 * relation.agreement:.0f} % put "
                f"{names[relation.outer]} outside (needs {100 * settings.decisive:.0f} %): "
                "they cross; give the order with --layers inner,...,outer")
        graph.add_edge(relation.inner, relation.outer)
    try:
        order = list(nx.lexicographical_topological_sort(graph))
    except nx.NetworkXUnfeasible:
        cycle = nx.find_cycle(graph)
        raise LayerOrderError(
            "the garments' layers form a cycle (" + " under ".join(
                names[edge[0]] for edge in cycle) + f" under {names[cycle[0][0]]}): "
            "give the order with --layers inner,...,outer") from None
    return order, relations


class LayerCollider:
    """A garment beneath, moving frame by frame (its Warp mesh refit, never rebuilt).

    Args:
        pos: ``(M, 3)`` first pose [m]; faces ``(F, 3)`` wound outward.
    """

    def __init__(self, pos: np.ndarray, faces: np.ndarray) -> None:
        self.mesh = _garment_mesh(pos, faces)

    def move(self, pos: np.ndarray) -> None:
        """Put the garment in the pose ``pos (M, 3)``."""
        from gnngarment.geometry.signed_distance import refit_mesh

        refit_mesh(self.mesh, pos)

    def heights(self, points: np.ndarray, settings: LayerSettings
                ) -> tuple[np.ndarray, np.ndarray]:
        """Height ``(N,)`` of ``points (N, 3)`` over this garment (``inf``: not over it
        within the search band) and its outward normal ``(N, 3)``."""
        return _heights(self.mesh, points, settings.search_band, settings.alignment)


def _as_frames(array: np.ndarray, name: str) -> np.ndarray:
    array = np.asarray(array, dtype=np.float64)
    if array.ndim == 2:
        array = array[None]
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"{name} must be (N, 3) or (T, N, 3), got {array.shape}")
    return array


def resolve_layer_collisions(outer: np.ndarray, faces: np.ndarray,
                             beneath: Sequence[tuple[np.ndarray, np.ndarray]],
                             settings: LayerSettings | None = None
                             ) -> tuple[np.ndarray, LayerStats]:
    """Move an outer garment's vertices out of the garments beneath it.

    Args:
        outer: ``(T, N, 3)`` or ``(N, 3)`` outer garment [m]; faces ``(F, 3)`` its
            triangles (the graph a push spreads over).
        beneath: ``(pos (T, M, 3) or (M, 3), faces (F_m, 3) wound outward)`` per garment
            under it, one pose per frame of ``outer``.
        settings: clearance and spread; default :class:`LayerSettings`.

    Returns:
        The resolved garment (shape and floating dtype of ``outer``) and
        :class:`LayerStats`. A frame with no vertex behind or closer than the clearance
        is returned unchanged, bit for bit.
    """
    settings = settings or LayerSettings()
    given = np.asarray(outer)
    dtype = given.dtype if np.issubdtype(given.dtype, np.floating) else np.float64
    pos = _as_frames(given, "outer")
    frames, count = pos.shape[:2]
    under = []
    for index, (inner_pos, inner_faces) in enumerate(beneath):
        inner = _as_frames(inner_pos, f"beneath[{index}]")
        if len(inner) != frames:
            raise ValueError(f"beneath[{index}] has {len(inner)} frames, outer {frames}")
        under.append((inner, LayerCollider(inner[0], inner_faces)))
    faces = np.asarray(faces, dtype=np.int64)
    graph = PushGraph(faces, count)
    stats = LayerStats(*(np.zeros(frames, dtype=np.int64) for _ in range(3)),
                       np.zeros(frames), np.zeros(frames, dtype=np.int64))
    clearance = float(settings.clearance)
    accept = clearance * (1 - _ACCEPT)
    resolved = pos.copy()

    def worst(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The smallest height over any garment beneath, and that garment's normal."""
        lowest = np.full(len(points), np.inf)
        normal = np.zeros((len(points), 3))
        for _, collider in under:
            height, outward = collider.heights(points, settings)
            lower = height < lowest
            lowest[lower], normal[lower] = height[lower], outward[lower]
        return lowest, normal

    for t in range(frames):
        for inner, collider in under:
            if t:
                collider.move(inner[t])
        height, normal = worst(pos[t])
        close = height < accept
        stats.through[t] = int((height < 0).sum())
        stats.close[t] = int(close.sum())
        if not close.any():
            continue
        need = np.where(close, clearance - height, 0.0)
        normal = np.where(close[:, None], normal, 0.0)
        shift = graph.smoothed_shift(need, normal, pos[t], settings.smoothing_radius,
                                     settings.smoothing_iterations)
        push = np.linalg.norm(shift, axis=1)
        check = np.flatnonzero(push > 0)
        for _ in range(settings.passes):
            after, outward = worst(pos[t][check] + shift[check])
            short = after < accept
            check = check[short]
            if not len(check):
                break
            shift[check] += (clearance - after[short])[:, None] * outward[short]
            push[check] = np.linalg.norm(shift[check], axis=1)
        if len(check):
            after, _ = worst(pos[t][check] + shift[check])
            stats.remaining[t] = int((after < accept).sum())
        resolved[t] = pos[t] + shift
        stats.moved[t] = int((push > 0).sum())
        stats.max_push[t] = float(push.max())
    out = resolved.astype(dtype, copy=False)
    return (out[0] if given.ndim == 2 else out), stats


def layer_penetration(outer: np.ndarray, beneath: np.ndarray, beneath_faces: np.ndarray,
                      settings: LayerSettings | None = None) -> np.ndarray:
    """Share ``(T,)`` of the outer garment's vertices behind the garment beneath.

    Args:
        outer: ``(T, N, 3)`` [m]; beneath ``(T, M, 3)`` [m], beneath_faces ``(F, 3)``
            wound outward.
        settings: search band and alignment; default :class:`LayerSettings`.
    """
    settings = settings or LayerSettings()
    outer, beneath = _as_frames(outer, "outer"), _as_frames(beneath, "beneath")
    collider = LayerCollider(beneath[0], beneath_faces)
    share = np.zeros(len(outer))
    for t in range(len(outer)):
        if t:
            collider.move(beneath[t])
        height, _ = collider.heights(outer[t], settings)
        share[t] = float((height < 0).mean())
    return share
