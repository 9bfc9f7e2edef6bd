"""Atomic ``.npz`` files and their file-naming read errors (gnngarment/io/npz.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gnngarment.io.npz import load_npz, save_npz_atomic


def test_round_trip_and_required_keys(tmp_path: Path) -> None:
    path = tmp_path / "sub" / "a.npz"
    arrays = {"x": np.arange(6).reshape(2, 3), "name": np.array("skirt")}
    save_npz_atomic(path, arrays)
    back = load_npz(path, required=("x",))
    np.testing.assert_array_equal(back["x"], arrays["x"])
    assert str(back["name"]) == "skirt"
    assert [p.name for p in path.parent.iterdir()] == ["a.npz"]  # no temporary left
    with pytest.raises(ValueError, match=rf"{path}: missing arrays \['y'\]"):
        load_npz(path, required=("x", "y"))


def test_missing_and_truncated_files_name_the_file(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=f"{tmp_path / 'absent.npz'}: file not found"):
        load_npz(tmp_path / "absent.npz")
    save_npz_atomic(tmp_path / "a.npz", {"x": np.zeros(1000)})
    truncated = tmp_path / "truncated.npz"
    truncated.write_bytes((tmp_path / "a.npz").read_bytes()[:300])
    with pytest.raises(ValueError, match=f"{truncated}: truncated or corrupt file"):
        load_npz(truncated)
