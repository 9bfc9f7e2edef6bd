"""Tiny CLOTH3D files written in the exact on-disk format (no golden blobs), shared by
the tests of `data_prep/cloth3d/`."""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import numpy as np

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
