"""MATLAB ``.mat`` files (v5, what CLOTH3D's ``info.mat`` is) read into plain Python.

The one place that calls :func:`scipy.io.loadmat`: the CLOTH3D motion loader
(:mod:`gnngarment.body.cloth3d_motion`) and the CLOTH3D dataset reader
(:mod:`data_prep.cloth3d.info`) both read through :func:`read_mat` and put their own
error type and checks on top.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["MatFileError", "finite_array", "finite_number", "read_mat", "whole_number"]


class MatFileError(ValueError):
    """A ``.mat`` file that is missing or cannot be read; the message names the file."""


def read_mat(path: str | Path) -> dict[str, Any]:
    """Every top-level variable of a MATLAB v5 file, as plain Python values.

    MATLAB structs become dicts, cell and struct arrays lists, scalars Python numbers,
    strings ``str``; numeric arrays stay numpy arrays, squeezed (``squeeze_me``: a
    ``(72, 1)`` array comes back ``(72,)``).

    Raises:
        MatFileError: the file is missing, or scipy cannot read it (e.g. a v7.3 HDF5
            file, a truncated file).
    """
    from scipy.io import loadmat

    path = Path(path)
    if not path.is_file():
        raise MatFileError(f"{path}: file not found")
    try:
        raw = loadmat(path, struct_as_record=False, squeeze_me=True)
    except NotImplementedError as error:  # scipy's message for v7.3 (HDF5) files
        raise MatFileError(f"{path}: cannot read MAT file ({error})") from error
    except Exception as error:  # scipy raises many kinds for a broken file
        raise MatFileError(f"{path}: cannot read MAT file "
                           f"({type(error).__name__}: {error})") from error
    return {key: plain_value(value) for key, value in raw.items() if not key.startswith("__")}


def plain_value(value: Any) -> Any:
    """One ``loadmat`` value → dicts, lists, Python scalars, ``str`` and numeric arrays."""
    from scipy.io.matlab import mat_struct

    if isinstance(value, mat_struct):
        return {name: plain_value(getattr(value, name)) for name in value._fieldnames}
    if isinstance(value, np.ndarray):
        if value.dtype == object:  # cell array or struct array
            return [plain_value(item) for item in value.ravel()]
        if value.dtype.kind == "U" and value.size == 0:  # how '' comes back
            return ""
        if value.ndim == 0:
            return value.item()
        return value
    if isinstance(value, np.generic):
        return value.item()
    return value


def finite_array(value: Any, name: str) -> np.ndarray:
    """A numeric variable (or struct field) as a float64 array, every element finite.

    Raises:
        ValueError: ``value`` is a string, a struct (dict), a cell array (list) or an
            array of a non-numeric type, or holds NaN/inf; the message names ``name``.
    """
    if isinstance(value, (str, bytes, dict)):
        raise ValueError(f"{name} is a {_kind(value)}, expected numbers")
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as error:  # a ragged cell array
        raise ValueError(f"{name} is not numeric ({error})") from None
    if array.dtype.kind not in "biuf":
        raise ValueError(f"{name} is a {_kind(value)}, expected numbers")
    array = array.astype(np.float64)
    if not np.isfinite(array).all():
        raise ValueError(f"{name} contains NaN or inf")
    return array


def finite_number(value: Any, name: str) -> float:
    """One finite number (a MATLAB scalar or a one-element array).

    Raises:
        ValueError: not numeric, not one element, or not finite.
    """
    array = finite_array(value, name)
    if array.size != 1:
        raise ValueError(f"{name} has shape {array.shape}, expected one number")
    return float(array.item())


def whole_number(value: Any, name: str) -> int:
    """One integer (MATLAB stores integers as doubles, so ``1.0`` counts).

    Raises:
        ValueError: not one finite number, or not a whole one.
    """
    number = finite_number(value, name)
    if number != int(number):
        raise ValueError(f"{name} is {number!r}, expected one integer")
    return int(number)


def _kind(value: Any) -> str:
    """What a value read from a ``.mat`` file is, in MATLAB's words."""
    if isinstance(value, (str, bytes)):
        return f"string ({value!r:.40})"
    if isinstance(value, dict):
        return "struct"
    if isinstance(value, list):
        return "cell array"
    return f"{np.asarray(value).dtype} array"
