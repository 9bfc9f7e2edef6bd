"""OBJ sequences: one file per frame, vertex order kept exactly, atomic writes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gnngarment.geometry.mesh_io import read_obj
from gnngarment.inference.export.obj_sequence import write_obj, write_obj_sequence
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
    assert [p.name for p in paths] == ["garment_0001.obj", "garment_0002.obj",
                                       "garment_0003.obj"]
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


def test_single_obj_has_header_and_only_v_and_f_lines(tmp_path: Path) -> None:
    path = write_obj(tmp_path / "rest.obj", np.eye(3), np.array([[0, 1, 2]]), header="a\nb")
    lines = path.read_text().splitlines()
    assert lines[:2] == ["# a", "# b"]
    assert {line.split()[0] for line in lines[2:]} == {"v", "f"}
    assert lines[-1] == "f 1 2 3"


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
