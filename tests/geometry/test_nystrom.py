"""Style descriptor: invariances on procedural garments, components, validators."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from gnngarment.geometry.nystrom import nystrom_descriptor


def tube_faces(num_rings: int, ring_size: int) -> np.ndarray:
    """Two triangles per quad between consecutive rings of ``ring_size`` vertices."""
    r = np.arange(num_rings - 1)[:, None] * ring_size
    c = np.arange(ring_size)[None, :]
    c_next = (c + 1) % ring_size
    a, b = (r + c).ravel(), (r + c_next).ravel()
    d, e = (r + ring_size + c_next).ravel(), (r + ring_size + c).ravel()
    return np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, e], 1)])


def skirt(res: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Open cone (A-line skirt): waist radius 0.17 m, hem 0.45 m, length 0.6 m.

    ``res`` multiplies the vertex count in both directions (2 -> ~4x faces).
    """
    around, rings = 48 * res, 16 * res + 1
    theta = 2 * np.pi * np.arange(around) / around
    t = np.linspace(0.0, 1.0, rings)[:, None]
    radius = 0.17 + 0.28 * t
    pos = np.stack(
        [radius * np.cos(theta), np.repeat(0.6 * (1 - t), around, 1), radius * np.sin(theta)], -1
    )
    return pos.reshape(-1, 3), tube_faces(rings, around)


def tshirt(res: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Cylinder body (r 0.18 m, 0.65 m) with a sleeve tube (0.25 m) sewn into a hole on
    each side. The hole-interior body vertices stay in ``pos`` unreferenced."""
    around, rings = 48 * res, 24 * res + 1
    theta = 2 * np.pi * np.arange(around) / around
    y = np.linspace(0.0, 0.65, rings)[:, None]
    ring = np.stack([0.18 * np.cos(theta), np.zeros(around), 0.18 * np.sin(theta)], -1)
    body = (ring[None] + y[..., None] * np.array([0.0, 1.0, 0.0])).reshape(-1, 3)
    keep = np.ones((rings - 1, around), dtype=bool)
    half, r0, r1 = 3 * res, rings - 1 - 8 * res, rings - 1 - 2 * res
    positions, faces = [body], []
    count = len(body)
    for centre, side in [(0, 1.0), (around // 2, -1.0)]:
        keep[r0:r1, (centre + np.arange(-half, half)) % around] = False
        cols = (centre + np.arange(-half, half + 1)) % around
        loop = np.concatenate(
            [
                r0 * around + cols,
                np.arange(r0 + 1, r1) * around + cols[-1],
                r1 * around + cols[::-1],
                np.arange(r1 - 1, r0, -1) * around + cols[0],
            ]
        )
        start = body[loop]
        centroid = start.mean(axis=0)
        radial = (start - centroid) * np.array([0.0, 1.0, 1.0])
        cuff = centroid + 0.08 * radial / np.linalg.norm(radial, axis=1, keepdims=True)
        previous = loop
        for k in range(1, 8 * res + 1):
            t = k / (8 * res)
            blend = min(1.0, 3.0 * t)  # hole outline -> round cuff over the first third
            ring_pos = (1 - blend) * start + blend * cuff
            ring_pos[:, 0] = (1 - blend) * start[:, 0] + blend * centroid[0] + side * 0.25 * t
            current = count + np.arange(len(loop))
            nxt = np.roll(np.arange(len(loop)), -1)
            faces += [
                np.stack([previous, previous[nxt], current[nxt]], 1),
                np.stack([previous, current[nxt], current], 1),
            ]
            positions.append(ring_pos)
            count += len(loop)
            previous = current
    body_faces = tube_faces(rings, around).reshape(2, rings - 1, around, 3)[:, keep]
    return np.concatenate(positions), np.concatenate([body_faces.reshape(-1, 3), *faces])


def subdivided(pos: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One level of midpoint subdivision (4x faces), unreferenced vertices dropped."""
    mesh = trimesh.Trimesh(pos, faces, process=False)
    mesh.remove_unreferenced_vertices()
    mesh = mesh.subdivide()
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


@pytest.fixture(scope="module")
def descriptors() -> dict[str, np.ndarray]:
    pos_s, faces_s = skirt(1)
    pos_t, faces_t = tshirt(1)
    return {
        "skirt": nystrom_descriptor(pos_s, faces_s),
        "skirt_2x": nystrom_descriptor(*skirt(2)),
        "skirt_sub": nystrom_descriptor(*subdivided(pos_s, faces_s)),
        "tshirt": nystrom_descriptor(pos_t, faces_t),
        "tshirt_2x": nystrom_descriptor(*tshirt(2)),
        "tshirt_sub": nystrom_descriptor(*subdivided(pos_t, faces_t)),
    }


def remesh_differences(d: dict[str, np.ndarray]) -> list[float]:
    return [
        rel(d["skirt_2x"], d["skirt"]),
        rel(d["skirt_sub"], d["skirt"]),
        rel(d["tshirt_2x"], d["tshirt"]),
        rel(d["tshirt_sub"], d["tshirt"]),
    ]


# ----------------------------------------------------------------------- invariances


def test_procedural_meshes_are_single_open_surfaces() -> None:
    for pos, faces in (skirt(1), tshirt(1), tshirt(2)):
        mesh = trimesh.Trimesh(pos, faces, process=False)
        assert len(mesh.split(only_watertight=False)) == 1
        assert not mesh.is_watertight  # open garment: waist/hem or neck/hem/cuffs


def test_output_shape_order_and_normalisation(descriptors: dict[str, np.ndarray]) -> None:
    for d in descriptors.values():
        assert d.shape == (64,) and d.dtype == np.float64
        assert np.isfinite(d).all()
        assert (np.diff(d) <= 0).all()
        assert d.min() > -1e-12
        # Eigenvalues of the area-weighted operator sum to trace(M G) = 1 exactly; the
        # Nyström approximation at the default width gets within a few percent.
        assert d.sum() == pytest.approx(1.0, abs=0.05)


def test_remeshing_at_twice_the_resolution(descriptors: dict[str, np.ndarray]) -> None:
    for difference in remesh_differences(descriptors):
        assert difference < 0.05


def test_units_do_not_matter() -> None:
    for pos, faces in (skirt(1), tshirt(1)):
        metres = nystrom_descriptor(pos, faces)
        # Symmetric procedural meshes have exact ties in the farthest-point sampling
        # that rounding of pos * 100 can break differently; without ties this is exact.
        assert rel(nystrom_descriptor(pos * 100.0, faces), metres) < 0.05


def test_vertex_relabelling(descriptors: dict[str, np.ndarray]) -> None:
    pos, faces = tshirt(1)
    perm = np.random.default_rng(0).permutation(len(pos))  # new vertex i = old perm[i]
    inverse = np.argsort(perm)
    relabelled = nystrom_descriptor(pos[perm], inverse[faces])
    assert rel(relabelled, descriptors["tshirt"]) < 0.05


def test_different_styles_differ_much_more_than_remeshes(
    descriptors: dict[str, np.ndarray],
) -> None:
    style = rel(descriptors["tshirt"], descriptors["skirt"])
    assert style > 4 * max(remesh_differences(descriptors))


def test_unreferenced_vertices_are_ignored() -> None:
    pos, faces = skirt(1)
    stray = np.concatenate([pos, [[5.0, 5.0, 5.0]]])
    np.testing.assert_allclose(
        nystrom_descriptor(stray, faces), nystrom_descriptor(pos, faces), atol=1e-12
    )


def test_matches_dense_area_weighted_spectrum() -> None:
    """Against the spectrum of the full N×N M^½ G M^½ on an ~800-vertex mesh."""
    from gnngarment.geometry.geodesics import geodesic_distances

    pos, faces = skirt(1)
    a, b, c = pos[faces[:, 0]], pos[faces[:, 1]], pos[faces[:, 2]]
    area = np.linalg.norm(np.cross(b - a, c - a), axis=1) / 2
    weight = np.bincount(faces.ravel(), weights=np.repeat(area / 3, 3)) / area.sum()
    pairs = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edge_index = np.concatenate([pairs.T, pairs[:, ::-1].T], axis=1)
    dist = geodesic_distances(pos, edge_index, np.arange(len(pos)))
    g = np.exp(-((dist / (0.5 * np.sqrt(area.sum()))) ** 2))
    root = np.sqrt(weight)
    dense = np.linalg.eigvalsh(root[:, None] * (g + g.T) / 2 * root[None, :])[::-1]
    assert dense.sum() == pytest.approx(1.0)
    approx = nystrom_descriptor(pos, faces)
    assert rel(approx[:10], dense[:10]) < 0.01


# ----------------------------------------------------------------- several components


def test_two_far_copies_split_the_spectrum() -> None:
    """G is block-diagonal with two equal blocks of area weight 1/2 each. The total
    area doubles, so s grows by sqrt(2): each block is half the single-copy operator
    at kernel_width * sqrt(2), and every eigenvalue appears twice."""
    pos, faces = skirt(1)
    two_pos = np.concatenate([pos, pos + np.array([10.0, 0.0, 0.0])])
    two_faces = np.concatenate([faces, faces + len(pos)])
    both = nystrom_descriptor(two_pos, two_faces, num_landmarks=64)
    single = nystrom_descriptor(pos, faces, num_landmarks=32, kernel_width=0.5 * np.sqrt(2))
    assert np.isfinite(both).all()
    np.testing.assert_allclose(both[:12], np.repeat(0.5 * single[:6], 2), rtol=0.02)
    # The gap between the pieces is irrelevant: their affinity is exactly zero.
    farther = np.concatenate([pos, pos + np.array([100.0, 0.0, 0.0])])
    np.testing.assert_allclose(nystrom_descriptor(farther, two_faces), both, atol=1e-9)


def test_many_small_components_analytic() -> None:
    """Nine disjoint unit equilateral triangles, 9 landmarks: FPS puts one landmark in
    each (infinite distances first), W = I, and each triangle is a rank-1 block
    ``u uᵀ`` with ``u = (1, g, g)``, ``g = exp(-(1 / σ)^2)``, vertex weights 1/27, so
    every eigenvalue is ``(1 + 2 g^2) / 27``."""
    corners = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, np.sqrt(3) / 2, 0.0]])
    pos = np.concatenate([corners + np.array([3.0 * k, 0.0, 0.0]) for k in range(9)])
    faces = np.arange(27).reshape(9, 3)
    sigma = 0.5 * np.sqrt(9 * np.sqrt(3) / 4)  # kernel_width * sqrt(total area)
    g = np.exp(-((1.0 / sigma) ** 2))
    d = nystrom_descriptor(pos, faces, num_landmarks=9)
    np.testing.assert_allclose(d, (1 + 2 * g**2) / 27, rtol=1e-10)


def test_fewer_vertices_than_landmarks_zero_pads() -> None:
    pos = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    d = nystrom_descriptor(pos, np.array([[0, 1, 2]]), num_landmarks=64)
    assert d.shape == (64,)
    assert np.isfinite(d).all() and (d[3:] == 0).all() and d[0] > 0


# ------------------------------------------------------------------------ validators


def triangle() -> tuple[np.ndarray, np.ndarray]:
    return np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), np.array([[0, 1, 2]])


@pytest.mark.parametrize(
    ("pos", "faces", "match"),
    [
        (np.zeros((3, 2)), np.array([[0, 1, 2]]), r"pos must have shape \(N, 3\)"),
        (np.zeros((3, 3), dtype=complex), np.array([[0, 1, 2]]), "real-valued"),
        (np.array([[0.0, 0, 0], [1, 0, 0], [0, np.nan, 0]]), np.array([[0, 1, 2]]), "NaN"),
        (triangle()[0], np.array([0, 1, 2]), r"faces must have shape \(F, 3\)"),
        (triangle()[0], np.array([[0, 1, 2, 0]]), r"faces must have shape \(F, 3\)"),
        (triangle()[0], np.array([[0.0, 1.0, 2.0]]), "faces must be an integer array"),
        (triangle()[0], np.zeros((0, 3), dtype=np.int64), "at least one triangle"),
        (triangle()[0], np.array([[0, 1, 3]]), r"outside \[0, 2\]"),
        (triangle()[0], np.array([[-1, 1, 2]]), r"outside \[0, 2\]"),
        (np.zeros((3, 3)), np.array([[0, 1, 2]]), "zero total surface area"),
    ],
)
def test_rejects_bad_mesh(pos: np.ndarray, faces: np.ndarray, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        nystrom_descriptor(pos, faces)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"num_landmarks": 0}, "num_landmarks must be >= 1"),
        ({"num_landmarks": 2.5}, "num_landmarks must be an int"),
        ({"num_landmarks": True}, "num_landmarks must be an int"),
        ({"kernel_width": 0.0}, "kernel_width must be a finite number > 0"),
        ({"kernel_width": -0.5}, "kernel_width must be a finite number > 0"),
        ({"kernel_width": float("nan")}, "kernel_width must be a finite number > 0"),
        ({"kernel_width": "0.5"}, "kernel_width must be a number"),
    ],
)
def test_rejects_bad_settings(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        nystrom_descriptor(*triangle(), **kwargs)  # type: ignore[arg-type]
