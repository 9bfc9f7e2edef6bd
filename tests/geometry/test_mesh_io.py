from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from gnngarment.geometry.errors import MeshError
from gnngarment.geometry.mesh_io import load_mesh, load_textured_mesh
from tests.meshes import interleave, random_disk


@pytest.mark.parametrize("extension", [".obj", ".ply", ".off", ".stl", ".glb"])
def test_round_trip_keeps_vertex_order(extension: str, tmp_path: Path) -> None:
    # A relabelled mesh: any reordering or welding by the loader would show.
    pos, faces = interleave(*random_disk(80, 2), seed=5)
    path = tmp_path / f"garment{extension}"
    trimesh.Trimesh(pos, faces, process=False).export(path)

    loaded_pos, loaded_faces = load_mesh(path)

    if extension == ".stl":  # STL stores triangle soups: 3 vertices per face
        np.testing.assert_allclose(loaded_pos[loaded_faces], pos[faces], atol=1e-5)
    else:
        np.testing.assert_allclose(loaded_pos, pos, atol=1e-5)
        np.testing.assert_array_equal(loaded_faces, faces)


def test_obj_keeps_duplicate_and_unreferenced_vertices_and_splits_quads(tmp_path: Path) -> None:
    path = tmp_path / "quad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 0\nv 9 9 9\n"
                    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                    "f 1/1 2/2 3/3 4/4\nf 2/2 5/1 3/3\n")
    pos, faces = load_mesh(path)
    assert pos.shape == (6, 3)  # vertex 5 duplicates vertex 1; vertex 6 unreferenced
    assert faces.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 2]]


def test_missing_unknown_and_broken_files_name_the_file(tmp_path: Path) -> None:
    with pytest.raises(MeshError, match="absent.obj: file not found"):
        load_mesh(tmp_path / "absent.obj")
    (tmp_path / "mesh.xyz").write_text("1 2 3\n")
    with pytest.raises(MeshError, match=r"mesh.xyz: unknown mesh format"):
        load_mesh(tmp_path / "mesh.xyz")
    (tmp_path / "broken.glb").write_bytes(b"glTF\x02\x00\x00\x00garbage")
    with pytest.raises(MeshError, match="broken.glb"):
        load_mesh(tmp_path / "broken.glb")
    (tmp_path / "bad.obj").write_text("v 0 0 0\nv 1 0\nf 1 2 3\n")
    with pytest.raises(MeshError, match=r"bad.obj:2: vertex line"):
        load_mesh(tmp_path / "bad.obj")
    (tmp_path / "cloud.obj").write_text("v 0 0 0\nv 1 0 0\n")
    with pytest.raises(MeshError, match="cloud.obj: the file holds no faces"):
        load_mesh(tmp_path / "cloud.obj")
    (tmp_path / "points.ply").write_text(
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0\n1 1 1\n")
    with pytest.raises(MeshError, match="points.ply"):
        load_mesh(tmp_path / "points.ply")


def test_obj_texture_coordinates_are_kept_per_corner_and_fan_split(tmp_path: Path) -> None:
    # A quad and a triangle sharing the edge 2–3, cut there in UV space (a seam): vertex 3
    # has vt 3 in the quad and vt 5 in the triangle. Relative (negative) indices too.
    path = tmp_path / "seam.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 1 0\n"
                    "vt 0 0\nvt 0.5 0\nvt 0.5 1\nvt 0 1\nvt 0.6 1\nvt 0.6 0 0\n"
                    "f 1/1 2/2 3/3 4/4\nf -4/-1 -2/-1 -3/-2\n")
    pos, faces, uv, uv_faces = load_textured_mesh(path)
    assert pos.shape == (5, 3)  # the v lines, nothing split or merged
    assert faces.tolist() == [[0, 1, 2], [0, 2, 3], [1, 3, 2]]
    assert uv_faces.tolist() == [[0, 1, 2], [0, 2, 3], [5, 5, 4]]
    np.testing.assert_array_equal(uv[[2, 4]], [[0.5, 1.0], [0.6, 1.0]])
    assert load_mesh(path)[1].tolist() == faces.tolist()  # the 2-tuple reader agrees


def test_obj_uvs_are_dropped_when_a_corner_has_none_and_bad_vt_indices_fail(
        tmp_path: Path) -> None:
    path = tmp_path / "partial.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                    "f 1/1 2/2 3/3\nf 2 4 3\n")
    mesh = load_textured_mesh(path)
    assert mesh.uv is None and mesh.uv_faces is None and len(mesh.faces) == 2
    (tmp_path / "bad.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/3\n")
    with pytest.raises(MeshError, match=r"bad.obj: faces name texture coordinates \(vt\) 1..3"):
        load_textured_mesh(tmp_path / "bad.obj")
    (tmp_path / "plain.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert load_textured_mesh(tmp_path / "plain.obj").uv is None


def test_glb_uvs_come_back_per_vertex_in_obj_convention(tmp_path: Path) -> None:
    pos, faces = random_disk(30, seed=3)
    uv = np.random.default_rng(0).uniform(size=(len(pos), 2))
    mesh = trimesh.Trimesh(pos, faces, process=False,
                           visual=trimesh.visual.TextureVisuals(uv=uv))
    path = tmp_path / "textured.glb"
    mesh.export(path)
    loaded = load_textured_mesh(path)
    np.testing.assert_allclose(loaded.pos, pos, atol=1e-6)
    np.testing.assert_allclose(loaded.uv, uv, atol=1e-6)  # v up, as given to trimesh
    np.testing.assert_array_equal(loaded.uv_faces, loaded.faces)
    plain = tmp_path / "plain.ply"
    trimesh.Trimesh(pos, faces, process=False).export(plain)
    assert load_textured_mesh(plain).uv is None


def test_obj_face_indices_written_as_floats_are_read(tmp_path: Path) -> None:
    """CLOTH3D's starter kit writes `f 6893.0 3.0 6892.0`; a fractional index is an error
    naming the file."""
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1.0 2.0 3.0\nf 2 4.0 3\n"
    (tmp_path / "floats.obj").write_text(text)
    _, faces = load_mesh(tmp_path / "floats.obj")
    np.testing.assert_array_equal(faces, [[0, 1, 2], [1, 3, 2]])
    (tmp_path / "half.obj").write_text(text.replace("f 2 4.0 3", "f 2 3.5 3"))
    with pytest.raises(MeshError, match="half.obj.*not a whole number"):
        load_mesh(tmp_path / "half.obj")
