from __future__ import annotations

import numpy as np
import pytest

from gnngarment.geometry.errors import MeshError
from gnngarment.geometry.validation import (
    check_mesh,
    remove_unreferenced_vertices,
    validate_mesh,
)
from tests.meshes import grid, tube, union


def test_a_clean_two_piece_garment_is_valid() -> None:
    pos, faces = union(tube(4, 6), grid(3, 3))
    report = validate_mesh(pos, faces, "skirt.obj")
    assert report.ok and report.num_components == 2
    assert any("2 connected components" in f for f in report.findings)


@pytest.mark.parametrize(
    "mutate,message",
    [
        (lambda p, f: (p[:0], f[:0]), "empty mesh"),
        (lambda p, f: (np.where(np.arange(len(p))[:, None] == 2, np.nan, p), f), "NaN/inf"),
        (lambda p, f: (np.where(np.arange(len(p))[:, None] == 1, np.inf, p), f), "NaN/inf"),
        (lambda p, f: (p, np.vstack([f, [[0, 1, len(p)]]])), "outside 0.."),
        (lambda p, f: (p, np.vstack([f, [[0, -1, 2]]])), "outside 0.."),
        (lambda p, f: (p, np.vstack([f, [[0, 0, 1]]])), "degenerate"),
        (lambda p, f: (p, np.vstack([f, [[0, 1, 2]]])), "degenerate"),  # collinear row
        (lambda p, f: (p, np.vstack([f, f[3][::-1]])), "duplicate faces"),
        (lambda p, f: (p[:, :2], f), r"expected \(N, 3\)"),
        (lambda p, f: (p, f[:, :2]), r"expected \(F, 3\)"),
        (lambda p, f: (p, f.astype(float)), "expected integers"),
    ],
)
def test_errors_raise_with_file_name(mutate, message: str) -> None:
    pos, faces = mutate(*grid(4, 4))
    with pytest.raises(MeshError, match=rf"^dress\.obj: invalid mesh: .*{message}"):
        validate_mesh(pos, faces, "dress.obj")


def test_degenerate_threshold_is_relative_to_size() -> None:
    pos, faces = grid(4, 4, spacing=1e-4)  # a tiny but perfectly valid mesh
    assert check_mesh(pos, faces).ok


def test_unreferenced_vertices_are_reported_and_removable() -> None:
    pos, faces = grid(3, 3)
    pos = np.vstack([pos[:4], [[5.0, 5.0, 5.0]], pos[4:]])  # insert vertex 4, unused
    faces = np.where(faces >= 4, faces + 1, faces)
    report = validate_mesh(pos, faces, "top.obj")
    assert report.unreferenced.tolist() == [4]
    assert any("unreferenced" in f for f in report.findings)

    clean_pos, clean_faces, kept = remove_unreferenced_vertices(pos, faces)
    assert len(clean_pos) == 9 and 4 not in kept.tolist()
    np.testing.assert_array_equal(clean_pos[clean_faces], pos[faces])
    np.testing.assert_array_equal(pos[kept], clean_pos)
    assert check_mesh(clean_pos, clean_faces).unreferenced.size == 0


def test_non_manifold_edges_are_reported_not_rejected() -> None:
    pos, faces = grid(2, 2)  # two triangles sharing the edge (0, 3)
    pos = np.vstack([pos, [[0.5, 0.5, 1.0]]])
    faces = np.vstack([faces, [[0, 3, 4]]])  # a third face on edge (0, 3)
    report = validate_mesh(pos, faces, "fin.obj")
    assert report.non_manifold_edges.tolist() == [[0, 3]]
    assert any("non-manifold" in f for f in report.findings)
