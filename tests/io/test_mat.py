"""The one MAT-file reader: nested structs, cells, scalars and strings as plain Python,
errors that name the file."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.io.mat import MatFileError, read_mat


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
