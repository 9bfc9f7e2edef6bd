"""OBJ sequences: one file per frame, vertex order kept exactly, atomic writes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gnngarment.geometry.mesh_io import read_obj, read_textured_obj
from gnngarment.inference.export.obj_sequence import write_obj_sequence
from gnngarment.io.obj import write_obj
from tests.inference.animations import rest_garment, tube_uv
from tests.meshes import random_disk


def test_sequence_keeps_vertex_order_and_numbers_frames(tmp_path: Path) -> None:
    pos, faces = random_disk(40, seed=1)
    rng = np.random.default_rng(0)
    order = rng.permutation(len(pos))  # an arbitrary "input" order must survive
    pos, faces = pos[order], np.argsort(order)[faces]
    frames = pos[None] + 0.01 * rng.normal(size=(3, *pos.shape))
    calls = []
    paths = write_obj_sequence(tmp_path / "seq", frames, faces, "garment",
                               progress=lambda done, total: calls.append((done, total)))
    assert [p.name for p in paths] == ["garment_0000.obj", "garment_0001.obj",
                                       "garment_0002.obj"]
    assert calls == [(1, 3), (2, 3), (3, 3)]
    for frame, path in zip(frames, paths, strict=True):
        back, back_faces = read_obj(path)
        np.testing.assert_allclose(back, frame, atol=1e-6)
        np.testing.assert_array_equal(back_faces, faces)
    assert sorted(p.name for p in (tmp_path / "seq").iterdir()) == [p.name for p in paths]


def test_long_sequences_pad_to_sort_and_first_frame_is_configurable(tmp_path: Path) -> None:
    frames = np.zeros((3, 3, 3))
    frames[:, 1, 0] = frames[:, 2, 1] = 1.0
    paths = write_obj_sequence(tmp_path, frames, np.array([[0, 1, 2]]), "body",
                               first_frame=9998)
    assert [p.name for p in paths] == ["body_09998.obj", "body_09999.obj", "body_10000.obj"]


@pytest.mark.parametrize(("frames", "faces", "message"), [
    (np.zeros((2, 3)), np.array([[0, 1, 2]]), r"frames must be \(T, N, 3\)"),
    (np.full((1, 3, 3), np.nan), np.array([[0, 1, 2]]), "NaN"),
    (np.zeros((1, 3, 3)), np.array([[0, 1, 3]]), "outside"),
    (np.zeros((1, 3, 3)), np.array([[0.0, 1.0, 2.0]]), "integers"),
])
def test_bad_input_is_rejected_before_writing(tmp_path: Path, frames, faces, message) -> None:
    with pytest.raises(ValueError, match=message):
        write_obj_sequence(tmp_path / "out", frames, faces)
    assert not (tmp_path / "out").exists()


def test_input_uvs_and_their_seam_survive_in_every_frame(tmp_path: Path) -> None:
    # The input as a DCC tool writes it: v, vt, then f v/vt corners (a cylinder unwrap
    # with a seam, so several vertices have two UVs).
    pos, faces = rest_garment()
    uv, uv_faces = tube_uv()
    corners = np.stack([faces, uv_faces], axis=-1) + 1
    face_lines = ["f " + " ".join(f"{v}/{t}" for v, t in corner) for corner in corners]
    source = tmp_path / "skirt.obj"
    source.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in pos.tolist())
                      + "".join(f"vt {u!r} {v!r}\n" for u, v in uv.tolist())
                      + "\n".join(face_lines) + "\n")
    mesh = read_textured_obj(source)
    rng = np.random.default_rng(1)
    frames = mesh.pos[None] + 0.01 * rng.normal(size=(3, *mesh.pos.shape))
    paths = write_obj_sequence(tmp_path / "seq", frames, mesh.faces, uv=mesh.uv,
                               uv_faces=mesh.uv_faces)
    for frame, path in zip(frames, paths, strict=True):
        lines = path.read_text().splitlines()
        assert [line for line in lines if line.startswith("f ")] == face_lines
        back = read_textured_obj(path)
        np.testing.assert_allclose(back.pos, frame, atol=1e-6)  # v lines: input order, count
        np.testing.assert_array_equal(back.faces, faces)
        np.testing.assert_array_equal(back.uv_faces, uv_faces)
        np.testing.assert_allclose(back.uv, uv, atol=1e-6)
    rest = write_obj(tmp_path / "rest.obj", mesh.pos, mesh.faces, uv=mesh.uv,
                     uv_faces=mesh.uv_faces)
    np.testing.assert_array_equal(read_textured_obj(rest).uv_faces, uv_faces)


def test_uvs_that_do_not_fit_the_faces_are_rejected(tmp_path: Path) -> None:
    frames, faces = np.zeros((1, 3, 3)), np.array([[0, 1, 2]])
    with pytest.raises(ValueError, match="together"):
        write_obj_sequence(tmp_path / "a", frames, faces, uv=np.zeros((3, 2)))
    with pytest.raises(ValueError, match="outside"):
        write_obj_sequence(tmp_path / "a", frames, faces, uv=np.zeros((3, 2)),
                           uv_faces=np.array([[0, 1, 3]]))
    assert not (tmp_path / "a").exists()
