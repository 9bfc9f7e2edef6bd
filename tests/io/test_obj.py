"""The library's one OBJ writer (gnngarment/io/obj.py): text, precision, checks, counting."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

from gnngarment.geometry.mesh_io import read_obj, read_textured_obj
from gnngarment.io.obj import count_obj_vertices, obj_text, write_obj


def test_single_obj_has_header_and_only_v_and_f_lines(tmp_path: Path) -> None:
    path = write_obj(tmp_path / "rest.obj", np.eye(3), np.array([[0, 1, 2]]), header="a\nb")
    lines = path.read_text().splitlines()
    assert lines[:2] == ["# a", "# b"]
    assert {line.split()[0] for line in lines[2:]} == {"v", "f"}
    assert lines[-1] == "f 1 2 3"


def test_float32_positions_read_back_exactly_in_file_order(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    pos = rng.normal(0, 2, (50, 3)).astype(np.float32)
    pos[0] = [1e-7, -0.0, 123.456]  # tiny, signed zero, large
    faces = rng.integers(0, len(pos), (30, 3))
    path = write_obj(tmp_path / "a.obj", pos, faces)
    back, back_faces = read_obj(path)
    np.testing.assert_array_equal(back.astype(np.float32), pos)  # 9 significant digits
    np.testing.assert_array_equal(back_faces, faces)
    assert count_obj_vertices(path) == len(pos)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporaries


def test_text_is_savetxt_percent_9g(tmp_path: Path) -> None:
    # The CLOTH3D writer's bytes before the OBJ writers were merged: numpy.savetxt with
    # "v %.9g %.9g %.9g" and 1-based "f %d %d %d" lines, nothing else.
    pos = np.random.default_rng(1).uniform(-1, 1, (7, 3))
    faces = np.array([[0, 1, 2], [2, 3, 4], [4, 5, 6]], dtype=np.int32)
    expected = io.StringIO()
    np.savetxt(expected, pos, fmt="v %.9g %.9g %.9g")
    np.savetxt(expected, faces.astype(np.int64) + 1, fmt="f %d %d %d")
    assert obj_text(pos, faces) == expected.getvalue()
    assert write_obj(tmp_path / "a.obj", pos, faces).read_text() == expected.getvalue()


def test_uvs_are_vt_lines_and_v_slash_vt_corners(tmp_path: Path) -> None:
    pos = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]])
    uv_faces = np.array([[0, 1, 2], [4, 2, 3]])
    path = write_obj(tmp_path / "uv.obj", pos, faces, uv=uv, uv_faces=uv_faces)
    lines = path.read_text().splitlines()
    assert lines[-2:] == ["f 1/1 2/2 3/3", "f 1/5 3/3 4/4"]
    assert [line for line in lines if line.startswith("vt ")][-1] == "vt 0.5 0.5"
    back = read_textured_obj(path)
    np.testing.assert_array_equal(back.uv, uv)
    np.testing.assert_array_equal(back.uv_faces, uv_faces)


@pytest.mark.parametrize(("pos", "faces", "extra", "message"), [
    (np.zeros((3, 2)), np.array([[0, 1, 2]]), {}, r"pos has shape \(3, 2\), expected \(N, 3\)"),
    (np.zeros((3, 3)), np.array([[0.0, 1.0, 2.0]]), {}, r"expected \(F, 3\) integers"),
    (np.full((3, 3), np.nan), np.array([[0, 1, 2]]), {}, "pos contains NaN or inf"),
    (np.zeros((3, 3)), np.array([[0, 1, 3]]), {}, r"face indices span \[0, 3\], outside \[0, 2\]"),
    (np.zeros((3, 3)), np.array([[0, 1, 2]]), {"uv": np.zeros((3, 2))}, "given together"),
    (np.zeros((3, 3)), np.array([[0, 1, 2]]),
     {"uv": np.zeros((3, 2)), "uv_faces": np.array([[0, 1, 3]])}, "uv_faces indices span"),
])
def test_bad_meshes_are_rejected_naming_the_file(tmp_path: Path, pos, faces, extra,
                                                 message) -> None:
    path = tmp_path / "bad.obj"
    with pytest.raises(ValueError, match=message) as caught:
        write_obj(path, pos, faces, **extra)
    assert str(caught.value).startswith(f"{path}: ")
    assert not list(tmp_path.iterdir())


def test_vertex_count_reads_only_v_lines(tmp_path: Path) -> None:
    path = tmp_path / "a.obj"
    path.write_text("# v 1 2 3\nv 0 0 0\n  v 1 0 0\nvt 0 0\nvn 0 0 1\n\tv 0 1 0\nf 1 2 3\n")
    assert count_obj_vertices(path) == 3
    with pytest.raises(OSError):
        count_obj_vertices(tmp_path / "missing.obj")
