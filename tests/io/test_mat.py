"""The one MAT-file reader: nested structs, cells, scalars and strings as plain Python,
errors that name the file."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.io.mat import MatFileError, finite_array, finite_number, read_mat, whole_number


def test_structs_cells_scalars_and_strings_come_back_plain(tmp_path) -> None:
    from scipy.io import savemat

    path = tmp_path / "info.mat"
    cells = np.empty(2, dtype=object)
    cells[:] = ["a", "bc"]
    savemat(path, {"poses": np.arange(6.0).reshape(3, 2), "gender": 1, "name": "",
                   "outfit": {"Top": {"fabric": "silk", "size": 2.5}}, "cells": cells})
    values = read_mat(path)
    assert values["poses"].shape == (3, 2) and values["poses"][2, 1] == 5.0
    assert values["gender"] == 1 and isinstance(values["gender"], int)
    assert values["name"] == ""
    assert values["outfit"] == {"Top": {"fabric": "silk", "size": 2.5}}
    assert values["cells"] == ["a", "bc"]
    assert not any(key.startswith("__") for key in values)


def test_missing_and_broken_files_are_named(tmp_path) -> None:
    path = tmp_path / "info.mat"
    with pytest.raises(MatFileError, match=f"{path}: file not found"):
        read_mat(path)
    path.write_bytes(b"MATLAB 5.0 MAT-file" + bytes(100))
    with pytest.raises(MatFileError, match=f"{path}: cannot read MAT file"):
        read_mat(path)


@pytest.mark.parametrize(("value", "message"), [
    ("abc", "poses is a string .'abc'., expected numbers"),
    ("1.5", "poses is a string"),  # numpy would parse it as a float
    ({"a": 1}, "poses is a struct, expected numbers"),
    (["a", 1.0], "poses is a cell array, expected numbers"),
    (np.array(["a", "b"], dtype=object), "poses is a object array, expected numbers"),
    (np.array([1.0, np.nan]), "poses contains NaN or inf"),
])
def test_values_of_the_wrong_type_are_named(value, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        finite_array(value, "poses")


def test_numbers_and_integers() -> None:
    assert finite_array([1, 2], "x").dtype == np.float64
    assert finite_number(np.array([0.5]), "zrot") == 0.5
    assert whole_number(1.0, "gender") == 1
    with pytest.raises(ValueError, match="zrot has shape .2,., expected one number"):
        finite_number([1.0, 2.0], "zrot")
    with pytest.raises(ValueError, match="gender is 0.5, expected one integer"):
        whole_number(0.5, "gender")
