"""Accuracy and speed of the geodesics behind the garment style descriptor.

Prints five tables:

1. Edge-graph Dijkstra (what the library uses) and, if ``potpourri3d`` is installed,
   the heat method, against exact great-circle distances on unit icospheres.
2. The effect on the Nyström descriptor: each method's descriptor vs the descriptor
   built from exact distances (same landmarks, same kernel).
2b. The same shape under two triangulation styles (icosphere vs UV sphere).
3. Several connected components: what each method returns on the other piece.
4. Speed of the descriptor on a 20k-vertex garment-like mesh, and of Dijkstra variants.

Run from the repository root:

    .venv/bin/python benchmarks/geodesic_accuracy.py

``potpourri3d`` is optional and only used here (``pip install potpourri3d``).
"""

from __future__ import annotations

import time

import numpy as np
import trimesh
from scipy.sparse.csgraph import dijkstra

from gnngarment.geometry.geodesics import (
    _edge_graph,
    farthest_point_sampling,
    geodesic_distances,
)
from gnngarment.geometry.graph import edge_index_from_faces
from gnngarment.geometry.nystrom import (
    _lumped_area_weights,
    _nystrom_eigenvalues,
    nystrom_descriptor,
)

NUM_SOURCES = 16
NUM_LANDMARKS = 64
KERNEL_WIDTH = 0.5


def great_circle(pos: np.ndarray, sources: np.ndarray) -> np.ndarray:
    """Exact distances on the unit sphere. Shapes: (N, 3), (K,) -> (K, N).

    atan2(|a x b|, a . b) is accurate for tiny angles, unlike arccos(a . b).
    """
    a = pos[sources][:, None, :]
    cross = np.linalg.norm(np.cross(a, pos[None]), axis=-1)
    return np.arctan2(cross, np.einsum("kij,ij->ki", a, pos))


def heat_solver(pos: np.ndarray, faces: np.ndarray):
    try:
        import potpourri3d as pp3d
    except ImportError:
        return None
    return pp3d.MeshHeatMethodDistanceSolver(pos, faces)


def heat_rows(solver, sources: np.ndarray) -> np.ndarray:
    return np.stack([solver.compute_distance(int(s)) for s in sources])


def relative_errors(approx: np.ndarray, exact: np.ndarray) -> tuple[float, float]:
    mask = exact > 0
    err = np.abs(approx[mask] - exact[mask]) / exact[mask]
    return float(err.mean()), float(err.max())


def descriptor_from_rows(dist, landmarks, pos, faces) -> np.ndarray:
    weight, area = _lumped_area_weights(pos, faces)
    eig = _nystrom_eigenvalues(dist, landmarks, weight, KERNEL_WIDTH * np.sqrt(area))
    return np.sort(eig)[::-1]


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def sphere_tables() -> None:
    accuracy, effect = [], []
    for level in (3, 4, 5):
        mesh = trimesh.creation.icosphere(subdivisions=level)
        pos, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
        pos = pos / np.linalg.norm(pos, axis=1, keepdims=True)
        edge_index = edge_index_from_faces(faces, len(pos))
        sources = np.linspace(0, len(pos) - 1, NUM_SOURCES).astype(np.int64)
        exact = great_circle(pos, sources)

        start = time.perf_counter()
        dij = geodesic_distances(pos, edge_index, sources)
        t_dij = (time.perf_counter() - start) / NUM_SOURCES
        row = [level, len(pos), *relative_errors(dij, exact), t_dij * 1e3]

        landmarks, dij_rows = farthest_point_sampling(pos, edge_index, NUM_LANDMARKS)
        ref = descriptor_from_rows(great_circle(pos, landmarks), landmarks, pos, faces)
        eff = [level, len(pos), rel(descriptor_from_rows(dij_rows, landmarks, pos, faces), ref)]

        solver = heat_solver(pos, faces)
        if solver is not None:
            start = time.perf_counter()
            heat = heat_rows(solver, sources)
            t_heat = (time.perf_counter() - start) / NUM_SOURCES
            row += [*relative_errors(heat, exact), t_heat * 1e3]
            heat_desc = descriptor_from_rows(heat_rows(solver, landmarks), landmarks, pos, faces)
            eff.append(rel(heat_desc, ref))
        accuracy.append(row)
        effect.append(eff)

    print(f"\n1. Unit icosphere, {NUM_SOURCES} sources: relative error vs great-circle distance")
    head = "| subdiv | N | Dijkstra mean | Dijkstra max | ms/source |"
    if len(accuracy[0]) > 5:
        head += " heat mean | heat max | ms/source |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for r in accuracy:
        cells = [f"{r[0]}", f"{r[1]}", f"{r[2]:.4f}", f"{r[3]:.4f}", f"{r[4]:.2f}"]
        if len(r) > 5:
            cells += [f"{r[5]:.4f}", f"{r[6]:.4f}", f"{r[7]:.2f}"]
        print("| " + " | ".join(cells) + " |")

    print(
        f"\n2. Descriptor (K={NUM_LANDMARKS}, kernel_width={KERNEL_WIDTH}) vs the one from "
        "exact distances, same landmarks: relative L2"
    )
    head = "| subdiv | N | Dijkstra |" + (" heat |" if len(effect[0]) > 3 else "")
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for e in effect:
        print("| " + " | ".join([str(e[0]), str(e[1])] + [f"{v:.4f}" for v in e[2:]]) + " |")


def heat_descriptor(pos: np.ndarray, faces: np.ndarray):
    """Descriptor with heat-method distances from the library's landmarks (None if no
    potpourri3d)."""
    solver = heat_solver(pos, faces)
    if solver is None:
        return None
    landmarks, _ = farthest_point_sampling(
        pos, edge_index_from_faces(faces, len(pos)), NUM_LANDMARKS
    )
    return descriptor_from_rows(heat_rows(solver, landmarks), landmarks, pos, faces)


def triangulation_table() -> None:
    ico = trimesh.creation.icosphere(subdivisions=4)
    uv = trimesh.creation.uv_sphere(count=[64, 64])
    uv.merge_vertices()  # the UV sphere repeats its seam and pole vertices
    meshes = [(np.asarray(m.vertices), np.asarray(m.faces)) for m in (ico, uv)]
    print(
        f"\n2b. Same unit sphere, two triangulation styles: icosphere(4) N={len(meshes[0][0])}"
        f" vs uv_sphere(64x64) N={len(meshes[1][0])}: descriptor relative L2"
    )
    print("| method | relative difference |")
    print("|---|---|")
    print(
        f"| Dijkstra | {rel(nystrom_descriptor(*meshes[1]), nystrom_descriptor(*meshes[0])):.4f} |"
    )
    heat = [heat_descriptor(*m) for m in meshes]
    if heat[0] is not None:
        print(f"| heat | {rel(heat[1], heat[0]):.4f} |")


def components_table() -> None:
    mesh = trimesh.creation.icosphere(subdivisions=3)
    pos, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    n = len(pos)
    two_pos = np.concatenate([pos, pos + np.array([5.0, 0.0, 0.0])])
    two_faces = np.concatenate([faces, faces + n])
    dij = geodesic_distances(two_pos, edge_index_from_faces(two_faces, 2 * n), np.array([0]))[0]
    print("\n3. Two unit spheres 5 apart, source on the first: distances on the second")
    print("| method | min | max |")
    print("|---|---|---|")
    print(f"| Dijkstra | {dij[n:].min()} | {dij[n:].max()} |")
    solver = heat_solver(two_pos, two_faces)
    if solver is not None:
        heat = solver.compute_distance(0)
        print(f"| heat | {heat[n:].min():.4g} | {heat[n:].max():.4g} |")
        own = relative_errors(heat[None, :n], great_circle(pos, np.array([0])))
        print(
            f"(heat on the source's own sphere: mean/max relative error {own[0]:.4f}/{own[1]:.4f})"
        )


def garment_like_tube(around: int = 200, rings: int = 100) -> tuple[np.ndarray, np.ndarray]:
    """Flared open tube (a long skirt), 1 m long: around * rings vertices."""
    theta = 2 * np.pi * np.arange(around) / around
    t = np.linspace(0.0, 1.0, rings)[:, None]
    radius = 0.2 + 0.3 * t
    pos = np.stack(
        [radius * np.cos(theta), np.repeat(1.0 - t, around, 1), radius * np.sin(theta)], -1
    ).reshape(-1, 3)
    r = np.arange(rings - 1)[:, None] * around
    c = np.arange(around)[None, :]
    cn = (c + 1) % around
    a, b = (r + c).ravel(), (r + cn).ravel()
    d, e = (r + around + cn).ravel(), (r + around + c).ravel()
    return pos, np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, e], 1)])


def best_of(fn, repeats: int = 5) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def speed_table() -> None:
    pos, faces = garment_like_tube()
    edge_index = edge_index_from_faces(faces, len(pos))
    graph = _edge_graph(pos, edge_index)
    upper = graph.copy()
    upper.data[graph.indices <= np.repeat(np.arange(len(pos)), np.diff(graph.indptr))] = 0
    upper.eliminate_zeros()
    sources = np.arange(NUM_LANDMARKS) * (len(pos) // NUM_LANDMARKS)
    # Beyond 4 sigma the affinity is exp(-16) ~ 1e-7: a truncated search would be enough
    # for U, but not for farthest-point sampling, which needs the far distances.
    limit = 4 * KERNEL_WIDTH * np.sqrt(_lumped_area_weights(pos, faces)[1])
    rows = [
        ("nystrom_descriptor, K=64 (everything)", lambda: nystrom_descriptor(pos, faces)),
        (
            "farthest_point_sampling, K=64",
            lambda: farthest_point_sampling(pos, edge_index, NUM_LANDMARKS),
        ),
        (
            "64 x dijkstra(one index), symmetric csr, directed=True",
            lambda: [dijkstra(graph, directed=True, indices=int(s)) for s in sources],
        ),
        (
            "1 x dijkstra(64 indices), symmetric csr, directed=True",
            lambda: dijkstra(graph, directed=True, indices=sources),
        ),
        (
            "64 x dijkstra(one index), upper-triangular csr, directed=False",
            lambda: [dijkstra(upper, directed=False, indices=int(s)) for s in sources],
        ),
        (
            "1 x dijkstra(64 indices), upper-triangular csr, directed=False",
            lambda: dijkstra(upper, directed=False, indices=sources),
        ),
        (
            f"64 x dijkstra(one index, limit={limit:.2f} m = 4 sigma)",
            lambda: [dijkstra(graph, directed=True, indices=int(s), limit=limit) for s in sources],
        ),
    ]
    if heat_solver(pos[:3], np.array([[0, 1, 2]])) is not None:
        rows.append(
            (
                "heat method: factor + 64 solves (potpourri3d)",
                lambda: heat_rows(heat_solver(pos, faces), sources),
            )
        )
    print(f"\n4. Speed on a {len(pos)}-vertex, {len(faces)}-face open tube (best of 5)")
    print("| what | seconds |")
    print("|---|---|")
    for name, fn in rows:
        print(f"| {name} | {best_of(fn):.3f} |")


def main() -> None:
    sphere_tables()
    triangulation_table()
    components_table()
    speed_table()


if __name__ == "__main__":
    main()
