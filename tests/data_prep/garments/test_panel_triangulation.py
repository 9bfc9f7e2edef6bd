"""`triangulate` (with `interior_points`, `resolve_shared_chords` and `stitch`): a square
pattern sewn on three sides becomes a pouch, a disk whose one boundary is its opening."""

from __future__ import annotations

import numpy as np

from data_prep.garments.interior_points import diametral_conflicts, interior_points
from data_prep.garments.panel_triangulation import triangulate
from data_prep.garments.pattern import Pattern, resample
from gnngarment.geometry.boundary import boundary_loops


def pouch(spacing: float = 0.1) -> Pattern:
    """Unit square: one seam (right, bottom, left side) and one opening along the top."""
    seam = np.array([[0.0, 1.0], [0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    top = np.array([[1.0, 1.0], [0.0, 1.0]])

    def even(run: np.ndarray) -> np.ndarray:
        return resample(run, np.linalg.norm(np.diff(run, axis=0), axis=1), spacing)

    return Pattern(seams=[even(seam)], openings={-1: [even(top)], 1: [even(top)]},
                   order=[(0, 0), (1, 0)])


def test_a_pouch_is_a_disk_bounded_by_its_opening() -> None:
    mesh = triangulate(pouch(), {-1: 60, 1: 60}, np.random.default_rng(0))
    n = len(mesh.xz)
    edges = np.sort(np.concatenate([mesh.faces[:, [0, 1]], mesh.faces[:, [1, 2]],
                                    mesh.faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges[:, 0] * n + edges[:, 1], return_counts=True)
    assert counts.max() == 2  # manifold: no edge in three or four triangles
    assert n - len(counts) + len(mesh.faces) == 1  # Euler characteristic of a disk
    loops = boundary_loops(mesh.faces)
    assert len(loops) == 1
    assert (mesh.opening[loops[0]] == 1).all()  # the only boundary is the opening
    assert set(np.unique(mesh.side)) == {-1, 0, 1}
    # Oriented: every interior edge is used once in each direction.
    directed = np.concatenate([mesh.faces[:, [0, 1]], mesh.faces[:, [1, 2]], mesh.faces[:, [2, 0]]])
    assert len(np.unique(directed[:, 0] * n + directed[:, 1])) == len(directed)


def test_triangulate_is_seeded() -> None:
    first = triangulate(pouch(), {-1: 40, 1: 40}, np.random.default_rng(5))
    again = triangulate(pouch(), {-1: 40, 1: 40}, np.random.default_rng(5))
    other = triangulate(pouch(), {-1: 40, 1: 40}, np.random.default_rng(6))
    np.testing.assert_array_equal(first.faces, again.faces)
    np.testing.assert_array_equal(first.xz, again.xz)
    assert len(first.xz) != len(other.xz) or not np.array_equal(first.xz, other.xz)


def test_interior_points_are_inside_and_clear_of_the_boundary() -> None:
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    square = np.concatenate([resample(np.stack([a, b]), np.ones(1), 0.1)[:-1]
                             for a, b in zip(square, np.roll(square, -1, axis=0), strict=True)])
    points = interior_points(square, 100, np.random.default_rng(1))
    assert 70 <= len(points) <= 130
    assert ((points > 0) & (points < 1)).all()
    segments = np.stack([square, np.roll(square, -1, axis=0)], axis=1)
    assert not diametral_conflicts(points, segments).any()
