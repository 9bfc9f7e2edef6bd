"""info.mat: round trips, CLOTH3D's layout, malformed files named."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import scipy.io

from data_prep.cloth3d import (
    Cloth3DError,
    read_info,
    write_info,
)
from tests.data_prep.cloth3d.files import (
    assert_info_equal,
    cloth3d_info,
)


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
    ({"zrot": "north"}, "zrot is a string .*, expected numbers"),
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
