"""The library's PointCache2 reader/writer (gnngarment/io/point_cache.py), and data_prep's
CLOTH3D-error view of it."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from gnngarment.io.point_cache import (
    HEADER,
    PointCacheError,
    read_point_cache,
    read_point_cache_header,
    write_point_cache,
)


def test_pc2_round_trip_keeps_order_and_header(tmp_path: Path) -> None:
    positions = np.random.default_rng(0).normal(size=(5, 7, 3)).astype(np.float32)
    path = write_point_cache(tmp_path / "g.pc2", positions, start_frame=1.0)
    np.testing.assert_array_equal(read_point_cache(path), positions)
    header = read_point_cache_header(path)
    assert (header.n_samples, header.n_points) == (5, 7)
    assert (header.start_frame, header.sample_rate) == (1.0, 1.0)
    raw = path.read_bytes()
    assert HEADER.unpack(raw[:32]) == (b"POINTCACHE2\0", 1, 7, 1.0, 1.0, 5)
    # Payload: frame-major, xyz per point, little-endian float32.
    assert struct.unpack("<3f", raw[32 + 12 * 8:32 + 12 * 9]) == tuple(positions[1, 1])
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_library_errors_are_value_errors_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "x.pc2"
    with pytest.raises(PointCacheError, match=f"{path}: point cache not found"):
        read_point_cache(path)
    path.write_bytes(b"POINTCACHE2\0")
    with pytest.raises(ValueError, match="shorter than the 32-byte"):
        read_point_cache(path)


def test_data_prep_reexport_raises_both_error_types(tmp_path: Path) -> None:
    from data_prep.cloth3d import Cloth3DError
    from data_prep.cloth3d import read_point_cache as cloth3d_read

    path = tmp_path / "Skirt.pc16"
    path.write_bytes(b"POINTCACHE3\0" + bytes(20))
    for error_type in (Cloth3DError, PointCacheError):
        with pytest.raises(error_type, match="wrong magic"):
            cloth3d_read(path)
