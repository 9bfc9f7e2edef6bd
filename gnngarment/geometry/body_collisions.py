"""Penetration-free garments: move vertices inside (or too close to) the body out.

After the network, every frame: a garment vertex inside the posed body, or closer to its
surface than ``ε``, needs a push along the outward direction at its closest point of
the body **mesh** (an exact BVH query, :mod:`~gnngarment.geometry.signed_distance`) to
``ε`` outside. Moving only those vertices would leave spikes, so the push spreads over
the garment's edge graph with a linear falloff: a vertex at path length ``ℓ`` (along
garment edges) from a colliding vertex with push ``s`` moves by ``s (1 − ℓ / r)``
(``r`` = ``smoothing_radius``) along that vertex's direction, and where several such
tents overlap the largest wins (neighbouring displacements differ by at most
``s · edge / r``, whatever the mesh resolution). A few Jacobi passes of the uniform
Laplacian then blend the directions where they turn fast (deep inside a thin limb,
neighbours' closest points lie on opposite sides). Each colliding vertex keeps at least
its own push along its own direction throughout; then every moved vertex that may have
come too close is checked again and, if the spread pushed it inside or too close
elsewhere, projected out once more (no spreading): no vertex ends closer than ``ε``.

Inside means a winding number of at least 1 (one ray's signed crossings), not the
closest face's side: the posed body intersects itself (the upper arm sinks into the
chest with the arms down), and there a vertex in the chest can have its closest point on
the buried arm surface, which the pseudo-normal calls "outside". Such a vertex — inside,
with its closest point still inside just past that surface — is moved along the
shortest of 64 rays out of the union of the parts instead
(:meth:`BodyCollider._signed`).

The body must be a closed mesh with outward winding (inside/outside is undefined
otherwise): the body models give the body's largest connected component
(:class:`~gnngarment.body.anny_model.AnnyBodyModel` drops Anny's tongue and eyes).

Cost: one Warp mesh per call, refit per frame (not rebuilt); closest points are searched
only within ``search_band`` of the surface. A vertex farther away is outside or deep
inside; every vertex of a connected far region has the same status (an edge shorter
than twice the band cannot cross the surface between two far vertices), so one
winding-number ray per region decides it (benchmarks/collision_resolution_speed.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gnngarment.geometry.graph import edge_index_from_faces
from gnngarment.geometry.signed_distance import sphere_directions


@dataclass
class CollisionSettings:
    """Settings of :func:`resolve_collisions` (defaults mirror ``configs/collisions.yaml``).

    Attributes:
        epsilon: clearance [m]: every garment vertex ends at least this far outside.
        smoothing_radius: path length along garment edges over which a push falls off
            to zero [m].
        smoothing_iterations: Jacobi passes over the spread pushes (0 with a zero
            radius = move only the colliding vertices).
        search_band: closest body points are searched this far from each vertex [m]
            (raised to ``2 ε`` if smaller).
        passes: re-check / project-out rounds after the spread.
    """

    epsilon: float = 0.002
    smoothing_radius: float = 0.05
    smoothing_iterations: int = 4
    search_band: float = 0.02
    passes: int = 3


@dataclass
class CollisionStats:
    """What :func:`resolve_collisions` did, per frame ``(T,)``.

    Attributes:
        inside: vertices inside the body before.
        close: vertices inside or closer than ``ε`` before.
        moved: vertices moved (colliding ones and their neighbours).
        max_push: largest vertex displacement [m].
        remaining: vertices still closer than ``ε`` after (0 unless the body mesh is
            not closed or ``passes`` ran out).
    """

    inside: np.ndarray
    close: np.ndarray
    moved: np.ndarray
    max_push: np.ndarray
    remaining: np.ndarray


#: Relative slack on ``ε`` when checking the result (float32 queries).
_ACCEPT = 1e-3
#: How far past its closest surface point a point inside is tested for a buried
#: surface [m] (:meth:`BodyCollider._signed`).
_BURIED_STEP = 1e-4


#: The rays searched for the way out where the closest surface is buried: 64 directions,
#: about 26° apart, so the shortest found is within ~4 % of the true shortest exit of a
#: flat surface (the re-check passes then move the vertex to ε along that surface's normal).
_EXIT_RAYS = sphere_directions(64)


class PushGraph:
    """A garment's edge graph as the collision resolutions spread pushes over it.

    Attributes:
        indptr, neighbours: CSR rows of the graph (both directions), ``(N + 1,)``, ``(E,)``.
        smoothing: one Jacobi pass of the uniform Laplacian, ``x ← ½ (x + mean of the
            neighbours)``, as a sparse ``(N, N)`` matrix (isolated vertices kept).
    """

    def __init__(self, faces: np.ndarray, num_vertices: int) -> None:
        import scipy.sparse as sp

        source, target = edge_index_from_faces(faces, num_vertices)
        self.indptr = np.searchsorted(source, np.arange(num_vertices + 1))
        self.neighbours = target
        degree = np.diff(self.indptr)
        weight = np.repeat(0.5 / np.maximum(degree, 1), degree)
        self.smoothing = (sp.csr_matrix((weight, target, self.indptr),
                                        shape=(num_vertices, num_vertices))
                          + sp.diags(np.where(degree > 0, 0.5, 1.0))).tocsr()

    def smoothed_shift(self, need: np.ndarray, normal: np.ndarray, pos: np.ndarray,
                       radius: float, iterations: int) -> np.ndarray:
        """The displacement ``(N, 3)`` [m] that gives every vertex at least its push
        ``need (N,)`` [m] along its unit ``normal (N, 3)`` (0 where not pushed), spread
        over the graph with a linear falloff over ``radius`` (:func:`spread_pushes`) and
        ``iterations`` Jacobi passes, each topped up to the pushes again."""
        shift = spread_pushes(need, normal, pos, self.indptr, self.neighbours, radius)
        # A colliding vertex whose value came from a neighbour's tent moves along that
        # neighbour's direction: top it up to its own push along its own. Then Jacobi
        # passes blend the directions where they turn fast (deep in a thin limb,
        # neighbours' closest points lie on opposite sides), topping up after each.
        for step in range(iterations + 1):
            if step:
                shift = self.smoothing @ shift
            along = np.einsum("na,na->n", shift, normal)
            shift += np.maximum(need - along, 0.0)[:, None] * normal
        return shift


class BodyCollider:
    """A body mesh that moves frame by frame (refit, never rebuilt) and a garment's
    edge graph: the signed offsets of garment vertices from the body.

    Args:
        body_vertices: ``(N_b, 3)`` [m] first pose; body_faces ``(F_b, 3)``, closed,
            outward winding.
        faces: ``(F, 3)`` garment triangles over ``num_vertices`` vertices.
        band: closest-point search band [m].
    """

    def __init__(self, body_vertices: np.ndarray, body_faces: np.ndarray, faces: np.ndarray,
                 num_vertices: int, band: float) -> None:
        from gnngarment.geometry.signed_distance import warp_mesh

        self.mesh = warp_mesh(body_vertices, body_faces)
        self.band = float(band)
        self.num_vertices = int(num_vertices)
        self.graph = PushGraph(faces, num_vertices)
        self.indptr, self.neighbours = self.graph.indptr, self.graph.neighbours
        source, target = edge_index_from_faces(faces, num_vertices)
        once = source < target
        self._first, self._second = source[once], target[once]
        self._once_indptr = np.searchsorted(self._first, np.arange(num_vertices + 1))

    def move(self, body_vertices: np.ndarray) -> None:
        """Put the body in the pose ``body_vertices (N_b, 3)``."""
        from gnngarment.geometry.signed_distance import refit_mesh

        refit_mesh(self.mesh, body_vertices)

    def offsets(self, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance ``(N,)`` [m] (``inf``: outside, farther than the band) and unit
        outward direction ``(N, 3)`` of every garment vertex ``pos (N, 3)``."""
        import scipy.sparse as sp
        from scipy.sparse.csgraph import connected_components

        from gnngarment.geometry.signed_distance import surface_offsets, winding_numbers

        distance, direction = self._signed(pos, *surface_offsets(self.mesh, pos, self.band))
        far = ~np.isfinite(distance)
        if not far.any():
            return distance, direction
        # Far vertices joined by short edges share inside/outside: test one per region.
        a, b = self._first, self._second
        short = far[a] & far[b]
        step = pos[a[short]] - pos[b[short]]
        short[short] = np.einsum("ea,ea->e", step, step) < (2 * self.band) ** 2
        count = self.num_vertices
        graph = sp.csr_matrix((short.astype(np.int8), b, self._once_indptr),
                              shape=(count, count))
        graph.eliminate_zeros()
        _, labels = connected_components(graph, directed=False)
        regions, first = np.unique(labels[far], return_index=True)
        representatives = np.flatnonzero(far)[first]
        deep = regions[winding_numbers(self.mesh, pos[representatives]) >= 1]
        if len(deep):
            inside = far & np.isin(labels, deep)
            distance[inside], direction[inside] = self._deep(pos[inside])
        return distance, direction

    def offsets_of(self, pos: np.ndarray, moved: np.ndarray, was_far: np.ndarray,
                   push: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Offsets of the ``moved`` vertices only (indices ``(M,)``) at ``pos (N, 3)``.

        A vertex that was outside and farther than the band and moved less than twice
        the band cannot be deeper than the band inside now; any other vertex with no
        surface within the band is classified by its winding number.
        """
        from gnngarment.geometry.signed_distance import surface_offsets, winding_numbers

        points = pos[moved]
        distance, direction = self._signed(points, *surface_offsets(self.mesh, points, self.band))
        unsure = ~np.isfinite(distance) & ~(was_far[moved] & (push[moved] < 2 * self.band))
        if unsure.any():
            inside = np.zeros(len(points), dtype=bool)
            inside[unsure] = winding_numbers(self.mesh, points[unsure]) >= 1
            if inside.any():
                distance[inside], direction[inside] = self._deep(points[inside])
        return distance, direction

    def _deep(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_signed` offsets of points known to be inside, farther than the band."""
        from gnngarment.geometry.signed_distance import surface_offsets

        found = surface_offsets(self.mesh, points, inside=np.ones(len(points), dtype=bool))
        return self._signed(points, *found)

    def _signed(self, points: np.ndarray, distance: np.ndarray, closest: np.ndarray,
                direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The closest-point offsets of ``points (N, 3)`` (``surface_offsets``), signed by
        the winding number instead of the pseudo-normal, and the way out of the union
        where the closest surface is buried.

        The posed body intersects itself (an upper arm sunk into the chest, thighs
        pressed together): there the closest body point of a point inside may lie on
        a part's surface that is itself inside another part. The pseudo-normal then
        calls the point outside, and moving it to that surface leaves it inside; such
        a point gets the shortest ray out of the union instead
        (:func:`~gnngarment.geometry.signed_distance.union_exits`), its length as the
        depth. Points with no surface within the band (``inf``) are kept.
        """
        from gnngarment.geometry.signed_distance import union_exits, winding_numbers

        near = np.flatnonzero(np.isfinite(distance))
        if not len(near):
            return distance, direction
        distance, direction = distance.copy(), direction.copy()
        winding = winding_numbers(self.mesh, points[near])
        inside = winding >= 1
        length = np.abs(distance[near])
        toward = closest[near] - points[near]          # to the closest surface point
        on_surface = length < 1e-7
        unit = toward / np.where(on_surface, 1.0, length)[:, None]
        outward = np.where(inside[:, None], unit, -unit)
        outward[on_surface] = direction[near][on_surface]   # the face normal
        distance[near] = np.where(inside, -length, length)
        direction[near] = outward
        # Inside, and just past the closest surface point still inside: buried.
        check = near[inside]
        beyond = closest[check] + outward[inside] * _BURIED_STEP
        buried = winding_numbers(self.mesh, beyond) >= 1
        if buried.any():
            which = check[buried]
            depth, way = union_exits(self.mesh, points[which], winding[inside][buried],
                                     _EXIT_RAYS)
            found = np.isfinite(depth)
            distance[which[found]] = -depth[found]
            direction[which[found]] = way[found]
        return distance, direction


def spread_pushes(push: np.ndarray, direction: np.ndarray, pos: np.ndarray,
                  indptr: np.ndarray, neighbours: np.ndarray, radius: float) -> np.ndarray:
    """The largest linear falloff of every push over the garment's edge graph.

    Vertex ``j`` gets ``max_i s_i (1 − ℓ_ij / r)`` along the winning ``i``'s direction,
    with ``ℓ_ij`` the shortest path length along edges; ``i`` itself (``ℓ = 0``) keeps
    at least its own push. Label-correcting relaxation from the pushed vertices: each
    round visits only the vertices whose value rose in the round before.

    Shapes:
        push ``(N,)`` [m] (0 = not pushed), direction ``(N, 3)`` unit, pos ``(N, 3)``
        [m]; the graph as CSR ``indptr (N + 1,)``, ``neighbours (E,)`` (both
        directions); returns the displacement ``(N, 3)`` [m].
    """
    value = push.astype(np.float64).copy()
    if radius <= 0 or not (value > 0).any():
        return value[:, None] * direction
    count = len(value)
    pos = np.asarray(pos, dtype=np.float32)
    source = value.copy()          # the push of the tent each vertex's value comes from
    owner = np.arange(count)       # the vertex whose direction it moves along
    best = np.empty(count)
    frontier = np.flatnonzero(value > 0)
    while len(frontier):
        counts = indptr[frontier + 1] - indptr[frontier]
        edge = (np.arange(int(counts.sum()))
                + np.repeat(indptr[frontier] - np.cumsum(counts) + counts, counts))
        origin = np.repeat(frontier, counts)
        target = neighbours[edge]
        step = pos[target] - pos[origin]
        offer = value[origin] - source[origin] * (np.sqrt(np.einsum("ea,ea->e", step, step))
                                                  / radius)
        better = offer > value[target] * (1 + 1e-9) + 1e-12
        if not better.any():
            break
        origin, target, offer = origin[better], target[better], offer[better]
        best[target] = -np.inf
        np.maximum.at(best, target, offer)
        win = offer == best[target]    # ties: any winner (equal values)
        origin, target = origin[win], target[win]
        value[target] = offer[win]
        source[target] = source[origin]
        owner[target] = owner[origin]
        frontier = np.unique(target)
    return value[:, None] * direction[owner]


def _as_frames(array: Any, name: str) -> np.ndarray:
    array = np.asarray(array, dtype=np.float64)
    if array.ndim == 2:
        array = array[None]
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"{name} must be (N, 3) or (T, N, 3), got {array.shape}")
    return array


def _check_triangles(name: str, triangles: Any, limit: int) -> np.ndarray:
    triangles = np.asarray(triangles)
    if (triangles.ndim != 2 or triangles.shape[1] != 3
            or not np.issubdtype(triangles.dtype, np.integer)
            or (triangles.size and (triangles.min() < 0 or triangles.max() >= limit))):
        raise ValueError(f"{name} must be (F, 3) integer indices below {limit}, got "
                         f"{triangles.shape} {triangles.dtype}")
    return triangles.astype(np.int64)


def resolve_collisions(garment: np.ndarray, faces: np.ndarray, body_vertices: np.ndarray,
                       body_faces: np.ndarray, settings: CollisionSettings | None = None
                       ) -> tuple[np.ndarray, CollisionStats]:
    """Move garment vertices out of the body to at least ``ε`` from its surface.

    Args:
        garment: ``(T, N, 3)`` or ``(N, 3)`` garment vertices [m].
        faces: ``(F, 3)`` garment triangles (the graph the correction spreads over).
        body_vertices: ``(T, N_b, 3)`` or ``(N_b, 3)`` posed body [m], one pose per
            garment frame; body_faces ``(F_b, 3)``: a closed mesh, outward winding.
        settings: ``ε`` and the spread; default :class:`CollisionSettings`.

    Returns:
        The resolved garment (the shape of ``garment``; its dtype if floating) and
        :class:`CollisionStats`.

    Raises:
        ValueError: shapes or settings that do not fit.
    """
    settings = settings or CollisionSettings()
    given = np.asarray(garment)
    dtype = given.dtype if np.issubdtype(given.dtype, np.floating) else np.float64
    pos = _as_frames(given, "garment")
    body = _as_frames(body_vertices, "body_vertices")
    if body.shape[0] != pos.shape[0] or (given.ndim == 2) != (np.ndim(body_vertices) == 2):
        raise ValueError(f"body_vertices {np.shape(body_vertices)} must have one pose per "
                         f"garment frame {given.shape}")
    count = pos.shape[1]
    faces = _check_triangles("faces", faces, count)
    body_faces = _check_triangles("body_faces", body_faces, body.shape[1])
    if min(settings.epsilon, settings.smoothing_radius, settings.smoothing_iterations,
           settings.search_band, settings.passes) < 0:
        raise ValueError(f"collision settings must not be negative: {settings}")
    epsilon = float(settings.epsilon)
    collider = BodyCollider(body[0], body_faces, faces, count,
                            max(settings.search_band, 2 * epsilon))
    frames = len(pos)
    stats = CollisionStats(*(np.zeros(frames, dtype=np.int64) for _ in range(3)),
                           np.zeros(frames), np.zeros(frames, dtype=np.int64))
    resolved = pos.copy()
    accept = epsilon * (1 - _ACCEPT)
    for t in range(frames):
        if t:
            collider.move(body[t])
        distance, direction = collider.offsets(pos[t])
        close = distance < accept
        stats.inside[t] = int((distance < 0).sum())
        stats.close[t] = int(close.sum())
        if not close.any():
            continue
        need = np.where(close, epsilon - distance, 0.0)        # (N,) push length [m]
        normal = np.where(close[:, None], direction, 0.0)      # (N, 3)
        shift = collider.graph.smoothed_shift(need, normal, pos[t], settings.smoothing_radius,
                                              settings.smoothing_iterations)
        push = np.linalg.norm(shift, axis=1)
        was_far = ~np.isfinite(distance)
        # Check every moved vertex that may have come closer than ε (a vertex moved by
        # |δ| is still at least d − |δ| away), then only those the last pass moved again.
        lower = np.where(was_far, collider.band, distance) - push
        check = np.flatnonzero((push > 0) & (lower < accept))
        for _ in range(settings.passes):
            after, outward = collider.offsets_of(pos[t] + shift, check, was_far, push)
            short = after < accept
            check = check[short]
            if not len(check):
                break
            shift[check] += (epsilon - after[short])[:, None] * outward[short]
            push[check] = np.linalg.norm(shift[check], axis=1)
        if len(check):
            after, _ = collider.offsets_of(pos[t] + shift, check, was_far, push)
            stats.remaining[t] = int((after < accept).sum())
        resolved[t] = pos[t] + shift
        stats.moved[t] = int((push > 0).sum())
        stats.max_push[t] = float(push.max())
    out = resolved.astype(dtype, copy=False)
    return (out[0] if given.ndim == 2 else out), stats
