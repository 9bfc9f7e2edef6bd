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

__all__ = ["MatFileError", "read_mat"]


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
