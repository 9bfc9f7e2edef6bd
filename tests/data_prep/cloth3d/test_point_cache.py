"""The CLOTH3D view of PointCache2 files: pc16/pc2 round trips, corrupt caches named."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from data_prep.cloth3d import (
    Cloth3DError,
    read_point_cache,
    read_point_cache_header,
    write_point_cache,
)
from tests.data_prep.cloth3d.files import (
    HEADER,
    raw_cache,
)


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
