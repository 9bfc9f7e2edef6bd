"""Exact signed distance from points to a closed body mesh (numpy + scipy only).

trimesh's ``contains``/``signed_distance`` need ``rtree``, which we do not depend on, so
this is the classic construction: the closest point on the closest triangle (Ericson,
*Real-Time Collision Detection*, 5.1.5) and the sign from the angle-weighted
pseudo-normal of the feature (face, edge or vertex) it lies on (Bærentzen & Aanæs
2005), which is exact for a closed, consistently wound manifold. Candidate triangles come
from a k-d tree over triangle centroids; a point is re-queried with more candidates
until the k-th centroid is provably farther than the best triangle found, so the result
does not depend on ``k``.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from data_prep.garments.angles import corner_angles
from gnngarment.geometry.normals import face_normals


def closest_points_on_triangles(
    p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest point of each triangle ``(a, b, c)`` to ``p``, row by row.

    Shapes:
        p, a, b, c: ``(M, 3)``.
        returns: ``q (M, 3)``, ``region (M,)`` int (0/1/2 = vertex a/b/c, 3/4/5 = edge
        ab/bc/ca, 6 = interior), ``bary (M, 3)`` barycentric weights of ``q``.
    """
    ab, ac, ap = b - a, c - a, p - a
    d1 = np.einsum("ij,ij->i", ab, ap)
    d2 = np.einsum("ij,ij->i", ac, ap)
    bp = p - b
    d3 = np.einsum("ij,ij->i", ab, bp)
    d4 = np.einsum("ij,ij->i", ac, bp)
    cp = p - c
    d5 = np.einsum("ij,ij->i", ab, cp)
    d6 = np.einsum("ij,ij->i", ac, cp)
    vc = d1 * d4 - d3 * d2
    vb = d5 * d2 - d1 * d6
    va = d3 * d6 - d5 * d4
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ab = d1 / (d1 - d3)
        t_ca = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        total = va + vb + vc
        v_face = vb / total
        w_face = vc / total
    # Ericson's sequential tests, in order: the first region that matches wins.
    conditions = [
        (d1 <= 0) & (d2 <= 0),
        (d3 >= 0) & (d4 <= d3),
        (vc <= 0) & (d1 >= 0) & (d3 <= 0),
        (d6 >= 0) & (d5 <= d6),
        (vb <= 0) & (d2 >= 0) & (d6 <= 0),
        (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0),
    ]
    region = np.select(conditions, [0, 1, 3, 2, 5, 4], default=6)
    bary = np.zeros((len(p), 3))
    bary[region == 0, 0] = 1
    bary[region == 1, 1] = 1
    bary[region == 2, 2] = 1
    on = region == 3
    bary[on, 0], bary[on, 1] = 1 - t_ab[on], t_ab[on]
    on = region == 4
    bary[on, 1], bary[on, 2] = 1 - t_bc[on], t_bc[on]
    on = region == 5
    bary[on, 0], bary[on, 2] = 1 - t_ca[on], t_ca[on]
    on = region == 6
    bary[on, 1], bary[on, 2] = v_face[on], w_face[on]
    bary[on, 0] = 1 - v_face[on] - w_face[on]
    q = bary[:, :1] * a + bary[:, 1:2] * b + bary[:, 2:] * c
    return q, region, bary


SAMPLE_REACH = 0.005  # metres: every surface point lies this close to a tree sample


def _surface_samples(vertices: np.ndarray, faces: np.ndarray,
                     reach: float) -> tuple[np.ndarray, np.ndarray]:
    """Sample points ``(S, 3)`` and their triangle ``(S,)`` such that every surface point
    is within ``reach`` of a sample of its own triangle: the centroid of each small
    triangle, the centroids of an ``n × n`` subdivision of larger ones (a sub-triangle's
    reach is its parent's divided by ``n``)."""
    corners = vertices[faces]
    centroid = corners.mean(axis=1)
    own_reach = np.linalg.norm(corners - centroid[:, None], axis=2).max(axis=1)
    steps = np.maximum(np.ceil(own_reach / reach), 1).astype(np.int64)
    points, owners = [], []
    for n in np.unique(steps):
        mine = np.flatnonzero(steps == n)
        i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        up = i + j <= n - 1
        down = i + j <= n - 2
        # Barycentric (u, v) of the centroids of the upward and downward sub-triangles.
        u = np.concatenate([(i[up] + 1 / 3) / n, (i[down] + 2 / 3) / n])
        v = np.concatenate([(j[up] + 1 / 3) / n, (j[down] + 2 / 3) / n])
        w = 1.0 - u - v
        c = corners[mine]
        grid = (w[None, :, None] * c[:, None, 0] + u[None, :, None] * c[:, None, 1]
                + v[None, :, None] * c[:, None, 2])
        points.append(grid.reshape(-1, 3))
        owners.append(np.repeat(mine, len(u)))
    return np.concatenate(points), np.concatenate(owners)


class _Component:
    """One closed component: triangles, pseudo-normals, a tree of surface samples and an
    (X, Z) grid of triangles for ray casting."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        self.vertices = vertices
        self.faces = faces
        normals = self.face_normals = face_normals(vertices, faces)
        # Angle-weighted vertex pseudo-normals.
        vertex_normals = np.zeros_like(vertices)
        angles = corner_angles(vertices, faces)
        for k in range(3):
            np.add.at(vertex_normals, faces[:, k], normals * angles[:, k, None])
        self.vertex_normals = vertex_normals
        # Edge pseudo-normals: sum of the two faces' normals, looked up per (face, edge).
        pairs = np.stack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]], axis=1)
        keys = np.sort(pairs, axis=2).reshape(-1, 2)
        keys = keys[:, 0] * len(vertices) + keys[:, 1]
        unique, inverse = np.unique(keys, return_inverse=True)
        edge_normals = np.zeros((len(unique), 3))
        np.add.at(edge_normals, inverse, np.repeat(normals, 3, axis=0))
        self.face_edge_normals = edge_normals[inverse].reshape(len(faces), 3, 3)
        samples, self.sample_face = _surface_samples(vertices, faces, SAMPLE_REACH)
        self.tree = cKDTree(samples)
        self.vertex_tree = cKDTree(vertices)
        self.box = (vertices.min(axis=0), vertices.max(axis=0))
        self._ray_grid: tuple | None = None

    def box_distance(self, points: np.ndarray) -> np.ndarray:
        """``(P,)`` distance from each point to this component's bounding box (0 inside):
        a lower bound of the distance to the surface, and 0 for points inside it."""
        gap = np.maximum(self.box[0] - points, 0) + np.maximum(points - self.box[1], 0)
        return np.linalg.norm(gap, axis=1)

    def query(self, points: np.ndarray, exact_below: float = np.inf, k: int = 16
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Signed distance ``(P,)``, a lower bound ``(P,)`` of the unsigned distance,
        closest point ``(P, 3)`` and outward direction ``(P, 3)``.

        The distance is exact (and equals the bound) wherever the bound is below
        ``exact_below``: candidates grow until every unexamined triangle is provably
        farther; points already known to be farther than ``exact_below`` stop early with
        the closest triangle found so far.
        """
        count = len(points)
        distance = np.full(count, np.inf)
        bound = np.zeros(count)
        closest = np.zeros((count, 3))
        direction = np.zeros((count, 3))
        todo = np.arange(count)
        if np.isfinite(exact_below):
            # Points with no sample within reach of ``exact_below`` are that far at least;
            # they get the nearest vertex's distance and its pseudo-normal's side (the
            # tree query with an upper bound is cheap for them).
            nearest, _ = self.tree.query(points, k=1, distance_upper_bound=exact_below
                                         + SAMPLE_REACH)
            far = np.flatnonzero(~np.isfinite(nearest))
            if len(far):
                d_vertex, vertex = self.vertex_tree.query(points[far])
                offset = points[far] - self.vertices[vertex]
                sign = np.where(np.einsum("ij,ij->i", offset, self.vertex_normals[vertex]) < 0,
                                -1.0, 1.0)
                distance[far] = sign * d_vertex
                bound[far] = exact_below
                closest[far] = self.vertices[vertex]
                direction[far] = sign[:, None] * offset / np.maximum(d_vertex, 1e-12)[:, None]
                todo = np.flatnonzero(np.isfinite(nearest))
        total = len(self.sample_face)
        k = min(k, total)
        while len(todo):
            sample_distance, samples = self.tree.query(points[todo], k=k)
            sample_distance = sample_distance.reshape(len(todo), k)
            candidates = self.sample_face[samples.reshape(len(todo), k)]
            p = np.repeat(points[todo], k, axis=0)
            tri = self.faces[candidates.ravel()]
            q, region, _ = closest_points_on_triangles(
                p, self.vertices[tri[:, 0]], self.vertices[tri[:, 1]], self.vertices[tri[:, 2]])
            dist = np.linalg.norm(p - q, axis=1).reshape(len(todo), k)
            best = np.argmin(dist, axis=1)
            rows = np.arange(len(todo))
            flat = rows * k + best
            face = candidates[rows, best]
            reg = region[flat]
            pseudo = self.face_normals[face].copy()
            is_vertex = reg <= 2
            pseudo[is_vertex] = self.vertex_normals[tri[flat[is_vertex], reg[is_vertex]]]
            is_edge = (reg >= 3) & (reg <= 5)
            pseudo[is_edge] = self.face_edge_normals[face[is_edge], reg[is_edge] - 3]
            offset = points[todo] - q[flat]
            sign = np.where(np.einsum("ij,ij->i", offset, pseudo) < 0, -1.0, 1.0)
            d = dist[rows, best]
            unit = np.where(d[:, None] > 1e-12, offset / np.maximum(d, 1e-12)[:, None],
                            pseudo / np.maximum(np.linalg.norm(pseudo, axis=1), 1e-300)[:, None])
            # An unexamined triangle has all its samples beyond the k-th, so it is at least
            # that far minus the sample reach.
            lower = np.minimum(d, sample_distance[:, -1] - SAMPLE_REACH)
            done = (lower >= d) | (lower >= exact_below) | (k >= total)
            ids = todo[done]
            distance[ids] = sign[done] * d[done]
            bound[ids] = np.maximum(lower[done], 0.0)
            closest[ids] = q[flat][done]
            direction[ids] = (sign[:, None] * unit)[done]
            todo = todo[~done]
            k = min(4 * k, total)
        return distance, bound, closest, direction

    def inside(self, points: np.ndarray) -> np.ndarray:
        """``(P,)`` True for points inside (ray parity along +Y, robust to the distance
        query's approximations). Along Y because a body in T/A-pose is flat in the
        frontal plane: few triangles project onto any (X, Z) cell. The ray is sheared by
        a tiny irrational slope so it never passes exactly through an edge or vertex in
        practice."""
        shear = np.array([1.2345e-4, 0.0, 2.7182e-4])
        if self._ray_grid is None:
            self._ray_grid = self._build_ray_grid(shear)
        cell_size, origin, shape, starts, order = self._ray_grid
        xz = points[:, [0, 2]] - points[:, 1:2] * shear[[0, 2]]
        cell = np.floor((xz - origin) / cell_size).astype(np.int64)
        valid = ((cell >= 0) & (cell < shape)).all(axis=1)
        key = np.where(valid, cell[:, 0] * shape[1] + cell[:, 1], 0)
        begin = np.where(valid, starts[key], 0)
        end = np.where(valid, starts[key + 1], 0)
        counts = end - begin
        owner = np.repeat(np.arange(len(points)), counts)
        offsets = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        tri = self.faces[order[np.repeat(begin, counts) + offsets]]
        corners = self.vertices[tri]
        c_xz = corners[:, :, [0, 2]] - corners[:, :, 1:2] * shear[[0, 2]]
        p = xz[owner]
        # Barycentric coordinates of the point in the projected triangle.
        e1, e2, r = c_xz[:, 1] - c_xz[:, 0], c_xz[:, 2] - c_xz[:, 0], p - c_xz[:, 0]
        det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        safe = np.where(det != 0, det, 1.0)
        u = (r[:, 0] * e2[:, 1] - r[:, 1] * e2[:, 0]) / safe
        v = (e1[:, 0] * r[:, 1] - e1[:, 1] * r[:, 0]) / safe
        hit = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1)
        y_hit = corners[:, 0, 1] + u * (corners[:, 1, 1] - corners[:, 0, 1]) + v * (
            corners[:, 2, 1] - corners[:, 0, 1])
        crossing = hit & (y_hit > points[owner, 1])
        return (np.bincount(owner[crossing], minlength=len(points)) % 2) == 1

    def _build_ray_grid(self, shear: np.ndarray) -> tuple:
        corners = self.vertices[self.faces]
        xz = corners[:, :, [0, 2]] - corners[:, :, 1:2] * shear[[0, 2]]
        lo, hi = xz.min(axis=1), xz.max(axis=1)
        cell_size = 0.01
        origin = lo.min(axis=0) - 1e-6
        shape = np.floor((hi.max(axis=0) - origin) / cell_size).astype(np.int64) + 1
        first = np.floor((lo - origin) / cell_size).astype(np.int64)
        last = np.floor((hi - origin) / cell_size).astype(np.int64)
        cells, owners = [], []
        span = last - first + 1
        for dy in range(int(span[:, 0].max())):
            for dz in range(int(span[:, 1].max())):
                mine = (dy < span[:, 0]) & (dz < span[:, 1])
                cells.append((first[mine, 0] + dy) * shape[1] + first[mine, 1] + dz)
                owners.append(np.flatnonzero(mine))
        cells_all, owners_all = np.concatenate(cells), np.concatenate(owners)
        order = np.argsort(cells_all, kind="stable")
        starts = np.searchsorted(cells_all[order], np.arange(shape[0] * shape[1] + 1))
        return cell_size, origin, shape, starts, owners_all[order]


class BodyDistance:
    """Signed distance to a body made of one or more closed components (their union).

    Args:
        vertices: ``(N_b, 3)`` metres; faces: ``(F_b, 3)`` outward-wound triangles.
    """

    def __init__(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        import scipy.sparse as sp
        from scipy.sparse.csgraph import connected_components

        vertices = np.asarray(vertices, dtype=np.float64)
        faces = np.asarray(faces, dtype=np.int64)
        n = len(vertices)
        rows, cols = faces[:, [0, 1, 2]].ravel(), faces[:, [1, 2, 0]].ravel()
        graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
        _, labels = connected_components(graph, directed=False)
        face_label = labels[faces[:, 0]]
        self.components = []
        for label in np.unique(face_label):
            component_faces = faces[face_label == label]
            used = np.unique(component_faces)
            remap = np.full(n, -1, dtype=np.int64)
            remap[used] = np.arange(len(used))
            self.components.append(_Component(vertices[used], remap[component_faces]))

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """Exact signed distance ``(P,)`` in metres: positive outside, negative inside."""
        return self.query(points)[0]

    def query(self, points: np.ndarray, exact_below: float = np.inf
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Signed distance ``(P,)``, closest body point ``(P, 3)`` and the unit direction
        ``(P, 3)`` from the body towards outside there (for pushing points out).

        The union's signed distance is the minimum over components. Distances are exact
        up to ``exact_below`` metres; beyond it they may overestimate (the query stops
        as soon as a point is known to be farther). A component is only queried for the
        points inside its bounding box or closer to it than the best value so far.
        """
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        count = len(points)
        distance = np.full(count, np.inf)
        closest = np.zeros((count, 3))
        direction = np.zeros((count, 3))
        lower = np.stack([c.box_distance(points) for c in self.components], axis=1)
        order = np.argsort(lower, axis=1)
        for rank in range(len(self.components)):
            component_of = order[:, rank]
            bound = lower[np.arange(count), component_of]
            # A component can lower the value if it may be closer, or contain the point.
            active = (bound < distance) | (bound == 0)
            if not active.any():
                break
            for c in np.unique(component_of[active]):
                ids = np.flatnonzero(active & (component_of == c))
                d, _, q, n = self.components[c].query(points[ids], exact_below)
                better = d < distance[ids]
                ids = ids[better]
                distance[ids], closest[ids], direction[ids] = d[better], q[better], n[better]
        return distance, closest, direction

    def clearance(self, points: np.ndarray, threshold: float = 0.02
                  ) -> tuple[np.ndarray, np.ndarray]:
        """A robust check for tests: ``inside (P,)`` by ray parity (any component) and a
        lower bound ``(P,)`` of the unsigned distance to the body surface, exact below
        ``threshold`` metres (larger values are only guaranteed to be ``>= threshold``)."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        inside = np.zeros(len(points), dtype=bool)
        bound = np.full(len(points), np.inf)
        for component in self.components:
            near = np.flatnonzero(component.box_distance(points) < threshold)
            if len(near) == 0:
                continue
            inside[near] |= component.inside(points[near])
            _, lower, _, _ = component.query(points[near], exact_below=threshold)
            bound[near] = np.minimum(bound[near], lower)
        return inside, np.minimum(bound, threshold)
