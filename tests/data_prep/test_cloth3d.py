"""CLOTH3D reader/writer: tiny files written in the exact on-disk format, no golden blobs."""

from __future__ import annotations

import os
import re
import struct
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
    from_world,
    inspect_sequence,
    read_info,
    read_point_cache,
    read_point_cache_header,
    read_sequence,
    rest_alignment,
    scan_dataset,
    to_world,
    unroot_frames,
    world_transform,
    write_info,
    write_point_cache,
    write_sequence,
    z_rotation,
)
from gnngarment.geometry import load_mesh
from tests.meshes import grid, tube

HEADER = struct.Struct("<12siiffi")


def raw_cache(path: Path, values: np.ndarray, dtype: str = "<f2", magic: bytes = b"POINTCACHE2\0",
              version: int = 1, n_points: int | None = None, n_samples: int | None = None,
              start_frame: float = 0.0, sample_rate: float = 1.0) -> Path:
    """A point cache written byte by byte, independently of the module under test."""
    values = np.asarray(values)
    n_points = values.shape[1] if n_points is None else n_points
    n_samples = values.shape[0] if n_samples is None else n_samples
    path.write_bytes(HEADER.pack(magic, version, n_points, start_frame, sample_rate, n_samples)
                     + values.astype(dtype).tobytes())
    return path


def cloth3d_info(num_frames: int, outfit: tuple[str, ...] = ("Tshirt",), zrot: float = 0.4,
                 seed: int = 0) -> dict[str, Any]:
    """Fields as read_info returns them, plus the extras CLOTH3D and our synthetic set use."""
    rng = np.random.default_rng(seed)
    fabrics = ["cotton", "silk", "denim", "leather"]
    return {
        "poses": rng.normal(0, 0.2, (num_frames, 72)),
        "trans": rng.normal(0, 0.5, (num_frames, 3)),
        "shape": rng.normal(0, 1, 10),
        "gender": 1,
        "zrot": zrot,
        "outfit": {name: {"fabric": fabrics[i % 4],
                          "texture": {"type": "color", "data": rng.uniform(0, 1, 3)}}
                   for i, name in enumerate(outfit)},
        "camLoc": np.array([0.0, -6.0, 1.2]),
        "lights": {"sun": {"strength": 2.5, "direction": np.array([0.1, 0.2, -1.0])}},
        "tightness": np.array([0.3, 0.7]),
        "body_model": "anny",
        "phenotype": {"gender": 0.5, "age": 0.25, "muscle": 0.7, "weight": 0.4},
        "tags": ["walk", "synthetic"],
    }


def garment(num_frames: int, kind: str = "tube", seed: int = 0
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A tiny garment: rest mesh plus frames in [-1, 1] m (float16-friendly)."""
    rng = np.random.default_rng(seed)
    pos, faces = tube(4, 6) if kind == "tube" else grid(3, 4, 0.1)
    frames = pos[None] + rng.normal(0, 0.05, (num_frames, len(pos), 3))
    return pos, faces, frames.astype(np.float32)


def assert_info_equal(actual: dict[str, Any], expected: dict[str, Any]) -> None:
    assert list(actual) == list(expected)
    for key, value in expected.items():
        if isinstance(value, dict):
            assert isinstance(actual[key], dict), key
            assert_info_equal(actual[key], value)
        elif isinstance(value, np.ndarray):
            np.testing.assert_array_equal(actual[key], value, err_msg=key)
        else:
            assert actual[key] == value, key


# --------------------------------------------------------------------------- point caches


def test_pc16_round_trip_within_float16_precision(tmp_path: Path) -> None:
    rng = np.random.default_rng(1)
    positions = rng.uniform(-2, 2, (5, 7, 3))
    path = write_point_cache(tmp_path / "a.pc16", positions, start_frame=3, sample_rate=0.5)

    back = read_point_cache(path)

    assert back.dtype == np.float32 and back.shape == (5, 7, 3)
    np.testing.assert_array_equal(back, positions.astype(np.float16).astype(np.float32))
    assert np.abs(back - positions).max() <= 2 * 2.0**-11  # half ulp of values up to 2
    header = read_point_cache_header(path)
    assert (header.n_samples, header.n_points) == (5, 7)
    assert (header.start_frame, header.sample_rate, header.dtype) == (3.0, 0.5, np.float16)


def test_pc2_round_trip_is_exact_and_bytes_follow_the_spec(tmp_path: Path) -> None:
    positions = np.random.default_rng(2).normal(0, 10, (4, 3, 3)).astype(np.float32)
    path = write_point_cache(tmp_path / "a.pc2", positions)

    np.testing.assert_array_equal(read_point_cache(path), positions)
    # Decode the file by hand: what Blender's or 3ds Max's PC2 importers would see.
    data = path.read_bytes()
    assert HEADER.unpack(data[:32]) == (b"POINTCACHE2\0", 1, 3, 0.0, 1.0, 4)
    np.testing.assert_array_equal(np.frombuffer(data[32:], "<f4").reshape(4, 3, 3), positions)


def test_reader_reads_a_hand_written_pc16_and_frame_slices(tmp_path: Path) -> None:
    values = np.arange(4 * 2 * 3, dtype=np.float32).reshape(4, 2, 3) / 8
    path = raw_cache(tmp_path / "b.pc16", values)
    np.testing.assert_array_equal(read_point_cache(path), values)
    np.testing.assert_array_equal(read_point_cache(path, frames=slice(1, 3)), values[1:3])
    np.testing.assert_array_equal(read_point_cache(path, frames=slice(None, None, 2)),
                                  values[::2])


def test_empty_cache_reads_as_zero_frames(tmp_path: Path) -> None:
    path = write_point_cache(tmp_path / "empty.pc16", np.zeros((0, 5, 3)))
    assert read_point_cache(path).shape == (0, 5, 3)


def test_value_type_follows_extension_unless_told(tmp_path: Path) -> None:
    positions = np.full((1, 2, 3), 0.1)
    with pytest.raises(ValueError, match="contradicts the extension"):
        write_point_cache(tmp_path / "a.pc16", positions, half=False)
    with pytest.raises(ValueError, match="unknown point cache extension"):
        write_point_cache(tmp_path / "a.cache", positions)
    path = write_point_cache(tmp_path / "a.cache", positions, half=False)
    assert read_point_cache(path, half=False)[0, 0, 0] == np.float32(0.1)
    with pytest.raises(Cloth3DError, match="unknown point cache extension"):
        read_point_cache(path)


def test_writer_rejects_bad_positions(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"expected \(T, N, 3\)"):
        write_point_cache(tmp_path / "a.pc16", np.zeros((4, 3)))
    with pytest.raises(ValueError, match="NaN or inf"):
        write_point_cache(tmp_path / "a.pc16", np.full((1, 1, 3), np.nan))
    with pytest.raises(ValueError, match="overflow float16"):
        write_point_cache(tmp_path / "a.pc16", np.full((1, 1, 3), 7e4))
    with pytest.raises(ValueError, match="invalid timing"):
        write_point_cache(tmp_path / "a.pc2", np.zeros((1, 1, 3)), sample_rate=0)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(("make", "message"), [
    (lambda p: raw_cache(p, np.zeros((3, 4, 3)), n_samples=4),
     r"truncated: header promises 4 frames × 4 points × 3 × 2 bytes = 96 bytes, file holds 72"),
    (lambda p: raw_cache(p, np.zeros((3, 4, 3)), n_samples=2), "trailing data"),
    (lambda p: raw_cache(p, np.zeros((3, 4, 3)), dtype="<f4"),
     "a float32 .pc2 file named .pc16"),
    (lambda p: raw_cache(p, np.zeros((1, 1, 3)), magic=b"POINTCACHE3\0"), "wrong magic"),
    (lambda p: raw_cache(p, np.zeros((1, 1, 3)), version=2), "unsupported PointCache2 version 2"),
    (lambda p: raw_cache(p, np.zeros((1, 1, 3)), n_points=-1), "negative counts"),
    (lambda p: raw_cache(p, np.zeros((1, 1, 3)), sample_rate=float("nan")), "invalid header"),
    (lambda p: p.write_bytes(b"POINTCACHE2\0\x01\0"), "shorter than the 32-byte"),
])
def test_corrupt_caches_raise_naming_file_and_problem(tmp_path: Path, make: Any,
                                                      message: str) -> None:
    path = tmp_path / "Skirt.pc16"
    make(path)
    with pytest.raises(Cloth3DError, match=message) as caught:
        read_point_cache(path)
    assert str(caught.value).startswith(f"{path}: ")
    with pytest.raises(Cloth3DError, match=message):  # the cheap check finds it too
        read_point_cache_header(path)


def test_missing_cache_names_the_file(tmp_path: Path) -> None:
    with pytest.raises(Cloth3DError, match=f"{tmp_path / 'x.pc16'}: point cache not found"):
        read_point_cache(tmp_path / "x.pc16")


def test_pc2_read_as_pc16_hint_works_the_other_way(tmp_path: Path) -> None:
    path = raw_cache(tmp_path / "a.pc2", np.zeros((2, 2, 3)), dtype="<f2")
    with pytest.raises(Cloth3DError, match="a float16 .pc16 file named .pc2"):
        read_point_cache(path)


# --------------------------------------------------------------------------- info.mat


@pytest.mark.parametrize("num_frames", [1, 6])
def test_info_round_trip(tmp_path: Path, num_frames: int) -> None:
    info = cloth3d_info(num_frames, outfit=("Tshirt", "Skirt"))
    path = write_info(tmp_path / "info.mat", info)

    back = read_info(path)

    assert back["poses"].shape == (num_frames, 72) and back["trans"].shape == (num_frames, 3)
    assert isinstance(back["gender"], int) and isinstance(back["zrot"], float)
    assert_info_equal(back, info)


@pytest.mark.parametrize("num_frames", [1, 6])
def test_info_is_stored_in_cloth3d_layout(tmp_path: Path, num_frames: int) -> None:
    info = cloth3d_info(num_frames)
    path = write_info(tmp_path / "info.mat", info)

    plain = scipy.io.loadmat(path)  # no squeezing: the true on-disk shapes
    assert plain["poses"].shape == (72, num_frames)
    assert plain["trans"].shape == (3, num_frames)
    np.testing.assert_array_equal(plain["poses"].T, info["poses"])
    assert plain["outfit"]["Tshirt"][0, 0]["fabric"][0, 0][0] == "cotton"
    squeezed = scipy.io.loadmat(path, struct_as_record=False, squeeze_me=True)
    expected = (72,) if num_frames == 1 else (72, num_frames)
    assert squeezed["poses"].shape == expected  # what CLOTH3D's own readers get
    assert squeezed["outfit"].Tshirt.fabric == "cotton"
    assert squeezed["phenotype"].age == 0.25


@pytest.mark.parametrize("num_frames", [1, 3])
def test_read_info_of_a_file_written_like_cloth3d(tmp_path: Path, num_frames: int) -> None:
    # Written with plain savemat in CLOTH3D's layout, not by write_info.
    poses = np.linspace(-1, 1, 72 * num_frames).reshape(72, num_frames)
    trans = np.arange(3 * num_frames, dtype=float).reshape(3, num_frames)
    scipy.io.savemat(tmp_path / "info.mat", {
        "poses": poses, "trans": trans, "shape": np.arange(10.0), "gender": 0.0,
        "zrot": np.array([[1.25]]), "camLoc": np.array([1.0, 2.0, 3.0]),
        "outfit": {"Trousers": {"fabric": "denim", "texture": {"type": "pattern",
                                                               "data": "stripes"}}},
        "lights": {"sun": np.array([0.1, 0.2, 0.3])}, "tightness": np.array([0.1, 0.9]),
    })

    info = read_info(tmp_path / "info.mat")

    np.testing.assert_array_equal(info["poses"], poses.T)
    np.testing.assert_array_equal(info["trans"], trans.T)
    assert info["gender"] == 0 and info["zrot"] == 1.25
    assert info["outfit"] == {"Trousers": {"fabric": "denim",
                                           "texture": {"type": "pattern", "data": "stripes"}}}
    np.testing.assert_array_equal(info["lights"]["sun"], [0.1, 0.2, 0.3])


def bad_info(path: Path, **changes: Any) -> Path:
    record = {"poses": np.zeros((72, 2)), "trans": np.zeros((3, 2)), "shape": np.zeros(10),
              "gender": 1, "zrot": 0.0, "outfit": {"Top": {"fabric": "silk"}}}
    record.update(changes)
    scipy.io.savemat(path, {k: v for k, v in record.items() if v is not None})
    return path


@pytest.mark.parametrize(("changes", "message"), [
    ({"zrot": None}, "missing field.s. zrot"),
    ({"poses": np.zeros((2, 72))}, r"poses has shape \(2, 72\), expected \(72, T\) or \(72,\)"),
    ({"trans": np.zeros((3, 3))}, "poses has 2 frames but trans has 3"),
    ({"gender": 0.5}, "gender is 0.5, expected one integer"),
    ({"zrot": "north"}, "expected one finite number"),
    ({"outfit": 3}, "outfit is a int, expected a struct"),
])
def test_malformed_info_raises_naming_the_file(tmp_path: Path, changes: dict[str, Any],
                                               message: str) -> None:
    path = bad_info(tmp_path / "info.mat", **changes)
    with pytest.raises(Cloth3DError, match=message) as caught:
        read_info(path)
    assert str(caught.value).startswith(f"{path}: ")


def test_missing_or_unreadable_info(tmp_path: Path) -> None:
    with pytest.raises(Cloth3DError, match="info.mat not found"):
        read_info(tmp_path / "info.mat")
    (tmp_path / "info.mat").write_bytes(b"MATLAB 5.0 MAT-file" + bytes(100))
    with pytest.raises(Cloth3DError, match=f"{tmp_path / 'info.mat'}: cannot read MAT file"):
        read_info(tmp_path / "info.mat")


def test_write_info_rejects_what_matlab_cannot_hold(tmp_path: Path) -> None:
    info = cloth3d_info(2)
    with pytest.raises(ValueError, match="'_private' is not a valid MATLAB field name"):
        write_info(tmp_path / "info.mat", {**info, "_private": 1})
    with pytest.raises(ValueError, match="phenotype.bad key"):
        write_info(tmp_path / "info.mat", {**info, "phenotype": {"bad key": 1.0}})
    with pytest.raises(ValueError, match="note: a NoneType cannot be stored"):
        write_info(tmp_path / "info.mat", {**info, "note": None})
    with pytest.raises(ValueError, match=r"poses has shape \(72, 2\), expected \(T, 72\)"):
        write_info(tmp_path / "info.mat", {**info, "poses": info["poses"].T})
    assert not list(tmp_path.iterdir())


# --------------------------------------------------------------------------- frames


def test_to_world_and_from_world_are_inverse() -> None:
    rng = np.random.default_rng(3)
    points, trans = rng.normal(size=(4, 9, 3)), rng.normal(size=(4, 3))
    np.testing.assert_allclose(from_world(to_world(points, trans, 0.8), trans, 0.8), points,
                               atol=1e-12)
    np.testing.assert_allclose(to_world(from_world(points, trans, -2.0), trans, -2.0), points,
                               atol=1e-12)
    assert to_world(points.astype(np.float32), trans, 0.8).dtype == np.float32


def test_moving_root_lands_where_expected() -> None:
    # A point 1 m above the root while the root walks +x at 1 m per frame; the sequence
    # is turned 90° about +z, so the walk goes along +y in the world.
    num_frames = 4
    trans = np.column_stack([np.arange(num_frames), np.zeros(num_frames), np.full(num_frames, 0.9)])
    points = np.tile([[0.0, 0.0, 1.0], [0.5, 0.0, 0.0]], (num_frames, 1, 1))  # (T, 2, 3)

    world = to_world(points, trans, np.pi / 2)

    t = np.arange(num_frames)
    np.testing.assert_allclose(world[:, 0], np.column_stack([0 * t, t, 1.9 + 0 * t]), atol=1e-12)
    np.testing.assert_allclose(world[:, 1], np.column_stack([0 * t, t + 0.5, 0.9 + 0 * t]),
                               atol=1e-12)
    # Joints as (T, 3) (one point per frame) use the same function.
    np.testing.assert_allclose(to_world(np.zeros((num_frames, 3)), trans, np.pi / 2)[:, :2],
                               np.column_stack([0 * t, t]), atol=1e-12)


def test_world_transform_matches_to_world_for_points_and_rigid_transforms() -> None:
    rng = np.random.default_rng(4)
    trans, zrot = rng.normal(size=(3, 3)), 1.1
    points = rng.normal(size=(3, 5, 3))
    transforms = world_transform(trans, zrot)
    homogeneous = np.concatenate([points, np.ones((3, 5, 1))], axis=2)
    np.testing.assert_allclose(np.einsum("tij,tnj->tni", transforms, homogeneous)[..., :3],
                               to_world(points, trans, zrot), atol=1e-12)
    # A joint's rigid transform G (cache frame) composed with W: its origin goes to_world.
    joint = np.eye(4)
    joint[:3, 3] = [0.1, 0.2, 0.3]
    np.testing.assert_allclose((transforms @ joint)[:, :3, 3],
                               to_world(np.tile(joint[:3, 3], (3, 1)), trans, zrot), atol=1e-12)


def test_z_rotation_direction() -> None:
    np.testing.assert_allclose(z_rotation(np.pi / 2) @ [1.0, 0, 0], [0, 1, 0], atol=1e-15)


def posed_about_the_root(rest: np.ndarray, root_rotations: np.ndarray) -> np.ndarray:
    """``(T, N, 3)``: ``rest`` carried by each frame's root rotation relative to the rest
    root (+90° about x), as a garment glued to the pelvis would be in the cache frame."""
    from scipy.spatial.transform import Rotation

    rest_root = Rotation.from_rotvec([np.pi / 2, 0, 0])
    return np.stack([(Rotation.from_rotvec(r) * rest_root.inv()).apply(rest)
                     for r in root_rotations])


def test_unroot_frames_undoes_the_root_rotation_relative_to_the_rest_root() -> None:
    rng = np.random.default_rng(3)
    rest = rng.normal(0, 0.2, (7, 3))
    roots = rng.normal(0, 1.0, (4, 3))
    frames = posed_about_the_root(rest, roots)
    np.testing.assert_allclose(unroot_frames(frames, roots), np.tile(rest, (4, 1, 1)),
                               atol=1e-12)
    # The rest pose's own root rotation (+90° about x) leaves a frame where it is.
    still = unroot_frames(rest[None], np.array([[np.pi / 2, 0, 0]]))[0]
    np.testing.assert_allclose(still, rest, atol=1e-12)


def test_rest_alignment_measures_turn_and_distance() -> None:
    """A template glued to the root: turn 0 and distance 0. The same template stored
    turned by −0.5 rad reads as turned +0.5 rad (what maps it back onto the frames);
    one stored 0.3 m too high reads as 0.3 m away with no turn."""
    rng = np.random.default_rng(4)
    rest = rng.normal(0, 0.2, (50, 3))
    roots = rng.normal(0, 1.0, (6, 3))
    frames = posed_about_the_root(rest, roots)

    good = rest_alignment(rest, frames, roots)
    assert good.turn.shape == good.distance.shape == (6,)
    np.testing.assert_allclose(good.turn, 0, atol=1e-9)
    assert abs(good.fitted_turn) < 1e-9 and good.median_distance < 1e-9
    assert good.problem() is None

    turned = rest_alignment(rest @ z_rotation(-0.5).T, frames, roots)
    np.testing.assert_allclose(turned.turn, 0.5, atol=1e-9)
    assert turned.fitted_turn == pytest.approx(0.5)
    assert "turned +29°" in turned.problem()
    assert turned.problem(max_turn=0.6, max_distance=1.0) is None

    high = rest_alignment(rest + np.array([0, 0, 0.3]), frames, roots)
    assert high.median_distance == pytest.approx(0.3)
    assert abs(high.fitted_turn) < 0.05
    assert "0.30 m (median) from its frames" in high.problem()


def test_frame_functions_validate_shapes() -> None:
    with pytest.raises(ValueError, match=r"trans has shape \(2, 3\), expected \(T, 3\) = \(4, 3\)"):
        to_world(np.zeros((4, 5, 3)), np.zeros((2, 3)), 0.0)
    with pytest.raises(ValueError, match=r"expected \(T, \.\.\., 3\)"):
        from_world(np.zeros((4, 2)), np.zeros((4, 3)), 0.0)
    with pytest.raises(ValueError, match=r"expected \(T, 3\) = \(4, 3\)"):
        unroot_frames(np.zeros((4, 5, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"frames have shape \(5, 3\), expected \(T, N, 3\)"):
        unroot_frames(np.zeros((5, 3)), np.zeros((5, 3)))
    with pytest.raises(ValueError, match=r"rest_pos has shape \(4, 3, 3\), expected \(N, 3\)"):
        rest_alignment(np.zeros((4, 3, 3)), np.zeros((1, 4, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="frames have 5 vertices but rest_pos has 4"):
        rest_alignment(np.zeros((4, 3)), np.zeros((1, 5, 3)), np.zeros((1, 3)))


# --------------------------------------------------------------------------- sequences


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
