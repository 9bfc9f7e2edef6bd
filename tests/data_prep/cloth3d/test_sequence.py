"""Sequences and dataset scans: round trips, quads and UVs, corrupt sequences reported;
atomic writes that keep the previous files."""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import scipy.io

import data_prep.cloth3d.sequence as sequence_module
import gnngarment.io.point_cache as point_cache_module
from data_prep.cloth3d import (
    Cloth3DError,
    atomic_write,
    inspect_sequence,
    read_info,
    read_point_cache,
    read_sequence,
    scan_dataset,
    to_world,
    write_info,
    write_point_cache,
    write_sequence,
)
from gnngarment.geometry import load_mesh
from tests.data_prep.cloth3d.files import (
    assert_info_equal,
    cloth3d_info,
    garment,
    raw_cache,
)


def write_tiny_sequence(folder: Path, num_frames: int = 3, zrot: float = 0.4,
                        half: bool = True) -> dict[str, tuple[np.ndarray, ...]]:
    garments = {"Tshirt": garment(num_frames, "tube", 1),
                "Trousers": garment(num_frames, "grid", 2)}
    write_sequence(folder, cloth3d_info(num_frames, tuple(garments), zrot), garments, half=half)
    return garments


@pytest.mark.parametrize("num_frames", [1, 5])
def test_sequence_round_trip(tmp_path: Path, num_frames: int) -> None:
    folder = tmp_path / "00017"
    garments = write_tiny_sequence(folder, num_frames, zrot=0.9)

    sequence = read_sequence(folder, fps=25)

    assert sequence.name == "00017" and sequence.fps == 25.0
    assert sequence.num_frames == num_frames and list(sequence.garments) == ["Tshirt", "Trousers"]
    assert sequence.joint_rotations.shape == (num_frames, 24, 3)
    for name, (rest_pos, faces, frames) in garments.items():
        got = sequence.garments[name]
        np.testing.assert_allclose(got.rest_pos, rest_pos, atol=1e-6)
        np.testing.assert_array_equal(got.faces, faces)
        np.testing.assert_allclose(got.frames, frames, atol=1e-3)  # float16
        # On disk the rest mesh is canonical, zrot not applied, as CLOTH3D stores it
        # (measured on a real sequence: tests/data_prep/test_cloth3d_real_sample.py).
        stored, _ = load_mesh(folder / f"{name}.obj")
        np.testing.assert_allclose(stored, rest_pos, atol=1e-6)
        np.testing.assert_allclose(sequence.world_frames(name),
                                   to_world(got.frames, sequence.trans, 0.9), atol=1e-6)
    # The result writes back unchanged (a Cloth3DGarment unpacks as the writer's tuple).
    write_sequence(tmp_path / "copy", sequence.info, sequence.garments)
    again = read_sequence(tmp_path / "copy")
    np.testing.assert_array_equal(again.garments["Tshirt"].frames,
                                  sequence.garments["Tshirt"].frames)
    assert_info_equal(again.info, sequence.info)


def test_reads_cloth3d_style_quads_and_uvs(tmp_path: Path) -> None:
    # A CLOTH3D-like rest OBJ: quads with UV indices, stored canonical (zrot is for the
    # world frame only and must not turn it).
    zrot = np.pi / 2
    canonical = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0.]])
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in canonical]
    lines += ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1", "f 1/1 2/2 3/3 4/4", "f 2/1 5/2 6/3 3/4"]
    (tmp_path / "Dress.obj").write_text("\n".join(lines) + "\n")
    frames = np.tile(canonical, (2, 1, 1))
    raw_cache(tmp_path / "Dress.pc16", frames)
    scipy.io.savemat(tmp_path / "info.mat", {
        "poses": np.zeros((72, 2)), "trans": np.zeros((3, 2)), "shape": np.zeros(10),
        "gender": 0, "zrot": zrot, "outfit": {"Dress": {"fabric": "silk"}}})

    sequence = read_sequence(tmp_path)

    dress = sequence.garments["Dress"]
    np.testing.assert_allclose(dress.rest_pos, canonical, atol=1e-12)
    assert dress.faces.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]]
    np.testing.assert_array_equal(dress.frames, frames)


def test_pc2_sequences_and_stale_caches(tmp_path: Path) -> None:
    folder = tmp_path / "seq"
    write_tiny_sequence(folder, half=True)
    garments = write_tiny_sequence(folder, half=False)  # rewrite as float32
    assert sorted(p.name for p in folder.iterdir()) == [
        "Trousers.obj", "Trousers.pc2", "Tshirt.obj", "Tshirt.pc2", "info.mat"]
    np.testing.assert_array_equal(read_sequence(folder).garments["Tshirt"].frames,
                                  garments["Tshirt"][2])


def corrupt(folder: Path, how: str) -> str:
    """Damage a good tiny sequence one way; returns the expected message pattern."""
    if how == "missing obj":
        (folder / "Trousers.obj").unlink()
        return f"{folder / 'Trousers.obj'}: missing; garment 'Trousers' is listed in the outfit"
    if how == "missing cache":
        (folder / "Tshirt.pc16").unlink()
        return f"{folder / 'Tshirt.pc16'}: missing \\(no .pc16 or .pc2\\)"
    if how == "two caches":
        write_point_cache(folder / "Tshirt.pc2", read_point_cache(folder / "Tshirt.pc16"))
        return "ambiguous, Tshirt.pc2 exists too"
    if how == "vertex count":
        values = read_point_cache(folder / "Tshirt.pc16")
        write_point_cache(folder / "Tshirt.pc16", values[:, :-1])
        return f"{folder / 'Tshirt.pc16'}: n_points = 23 but Tshirt.obj has 24 vertices"
    if how == "frame count":
        values = read_point_cache(folder / "Trousers.pc16")
        write_point_cache(folder / "Trousers.pc16", values[:-1])
        return "2 frames but poses/trans in info.mat have 3"
    if how == "truncated cache":
        data = (folder / "Tshirt.pc16").read_bytes()
        (folder / "Tshirt.pc16").write_bytes(data[:-10])
        return f"{folder / 'Tshirt.pc16'}: truncated"
    if how == "missing info":
        (folder / "info.mat").unlink()
        return f"{folder / 'info.mat'}: info.mat not found"
    if how == "unreadable info":
        (folder / "info.mat").write_bytes(b"\0" * 50)
        return f"{folder / 'info.mat'}: cannot read MAT file"
    if how == "info frames":
        info = read_info(folder / "info.mat")
        write_info(folder / "info.mat", {**info, "poses": info["poses"][:2],
                                         "trans": info["trans"][:2]})
        return "3 frames but poses/trans in info.mat have 2"
    raise AssertionError(how)


CORRUPTIONS = ["missing obj", "missing cache", "two caches", "vertex count", "frame count",
               "truncated cache", "missing info", "unreadable info", "info frames"]


@pytest.mark.parametrize("how", CORRUPTIONS)
def test_corrupt_sequences_raise_and_scan_reports_them(tmp_path: Path, how: str) -> None:
    write_tiny_sequence(tmp_path / "good")
    write_tiny_sequence(tmp_path / "bad")
    message = corrupt(tmp_path / "bad", how)

    with pytest.raises(Cloth3DError, match=message):
        read_sequence(tmp_path / "bad")
    good, bad = scan_dataset(tmp_path)
    assert good == [tmp_path / "good"]
    assert [folder for folder, _ in bad] == [tmp_path / "bad"]
    assert re.search(message, bad[0][1])


def test_empty_outfit_is_an_error(tmp_path: Path) -> None:
    write_info(tmp_path / "info.mat", {**cloth3d_info(2), "outfit": {}})
    assert read_info(tmp_path / "info.mat")["outfit"] == {}
    with pytest.raises(Cloth3DError, match="info.mat: outfit lists no garments"):
        read_sequence(tmp_path)


def test_obj_with_faces_past_its_vertices(tmp_path: Path) -> None:
    write_tiny_sequence(tmp_path)
    with open(tmp_path / "Trousers.obj", "a") as stream:
        stream.write("f 1 2 99\n")
    with pytest.raises(Cloth3DError, match="Trousers.obj: face indices span \\[1, 99\\]"):
        read_sequence(tmp_path)


def test_scan_does_not_read_payloads(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    write_tiny_sequence(tmp_path / "a")
    (tmp_path / ".hidden").mkdir()

    def no_payloads(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("payload read during a scan")

    monkeypatch.setattr(sequence_module, "read_payload", no_payloads)
    monkeypatch.setattr(point_cache_module, "read_payload", no_payloads)
    assert scan_dataset(tmp_path) == ([tmp_path / "a"], [])
    assert inspect_sequence(tmp_path / "a").garments["Tshirt"].num_vertices == 24


def test_scan_rejects_a_sequence_folder_or_missing_root(tmp_path: Path) -> None:
    write_tiny_sequence(tmp_path / "s")
    with pytest.raises(Cloth3DError, match="so it is a sequence folder"):
        scan_dataset(tmp_path / "s")
    with pytest.raises(Cloth3DError, match="dataset folder not found"):
        scan_dataset(tmp_path / "nowhere")


def test_write_sequence_checks_everything_before_writing(tmp_path: Path) -> None:
    info = cloth3d_info(3, ("Tshirt",))
    rest_pos, faces, frames = garment(3)
    folder = tmp_path / "s"
    with pytest.raises(ValueError, match="outfit lists \\['Tshirt'\\] but garments given"):
        write_sequence(folder, info, {"Skirt": (rest_pos, faces, frames)})
    with pytest.raises(ValueError, match=r"expected \(T, N, 3\) = \(3, 24, 3\)"):
        write_sequence(folder, info, {"Tshirt": (rest_pos, faces, frames[:2])})
    with pytest.raises(ValueError, match="faces must be"):
        write_sequence(folder, info, {"Tshirt": (rest_pos, faces + 100, frames)})
    with pytest.raises(ValueError, match="overflow float16"):
        write_sequence(folder, info, {"Tshirt": (rest_pos, faces, frames * 1e5)})
    with pytest.raises(ValueError, match="fps must be positive"):
        read_sequence(folder, fps=0)
    assert not folder.exists()


# --------------------------------------------------------------------------- atomic writes


def test_failed_write_keeps_the_old_file_and_leaves_no_temp(tmp_path: Path) -> None:
    path = tmp_path / "Tshirt.pc16"
    path.write_bytes(b"old")

    def half_then_fail(stream: Any) -> None:
        stream.write(b"new but incomplete")
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        atomic_write(path, half_then_fail)
    assert path.read_bytes() == b"old" and os.listdir(tmp_path) == ["Tshirt.pc16"]


def test_failed_cache_and_info_writes_keep_previous_files(tmp_path: Path,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    cache = write_point_cache(tmp_path / "a.pc16", np.zeros((2, 3, 3)))
    info = write_info(tmp_path / "info.mat", cloth3d_info(2))
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    def failing_fsync(descriptor: int) -> None:  # everything written, nothing renamed yet
        raise OSError("I/O error")

    monkeypatch.setattr(os, "fsync", failing_fsync)
    with pytest.raises(OSError, match="I/O error"):
        write_point_cache(cache, np.ones((4, 3, 3)))
    monkeypatch.undo()

    def partial_savemat(stream: Any, *args: Any, **kwargs: Any) -> None:
        stream.write(b"MATLAB 5.0 MAT-file, half written")
        raise RuntimeError("interrupted")

    monkeypatch.setattr("scipy.io.savemat", partial_savemat)
    with pytest.raises(RuntimeError, match="interrupted"):
        write_info(info, cloth3d_info(5))
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    assert read_info(info)["poses"].shape == (2, 72)


def test_written_files_respect_the_umask(tmp_path: Path) -> None:
    mask = os.umask(0o022)
    try:
        path = write_point_cache(tmp_path / "a.pc16", np.zeros((1, 1, 3)))
    finally:
        os.umask(mask)
    if os.name == "posix":
        assert path.stat().st_mode & 0o777 == 0o644


def test_reader_does_not_depend_on_the_body_package() -> None:
    # The CLOTH3D reader stays on file formats and array conventions; SMPL posing is
    # the body package's job and uses data_prep.cloth3d.frames, not the other way round.
    for source in Path(sequence_module.__file__).parent.glob("*.py"):
        assert "gnngarment.body" not in source.read_text(), source
