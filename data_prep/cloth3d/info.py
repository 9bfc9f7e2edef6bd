"""CLOTH3D ``info.mat``: per-sequence SMPL parameters, rotation and outfit.

On disk (MATLAB v5, one top-level variable per field, as the CLOTH3D starter kit reads it):

==============  ==================  ===============================================
field           stored as           returned by :func:`read_info` as
==============  ==================  ===============================================
``poses``       ``(72, T)``         ``(T, 72)`` float64, SMPL axis-angle, radians
``trans``       ``(3, T)``          ``(T, 3)`` float64, root translation, metres
``shape``       ``(10,)``           ``(10,)`` float64 SMPL betas
``gender``      scalar              ``int`` (0 female, 1 male)
``zrot``        scalar              ``float`` radians about +z
``outfit``      struct of structs   ``dict`` garment → ``{"fabric": str, "texture": {...}}``
others          anything            kept, structs as dicts (``camLoc``, ``lights``, ...)
==============  ==================  ===============================================

``scipy.io.loadmat(squeeze_me=True)`` squeezes a single-frame sequence's ``(72, 1)``
poses to ``(72,)`` and ``(3, 1)`` trans to ``(3,)``; :func:`read_info` always returns a
leading frame axis, so ``T = 1`` needs no special case downstream.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from data_prep.cloth3d.errors import Cloth3DError
from gnngarment.io.atomic import atomic_write
from gnngarment.io.mat import MatFileError, finite_array, finite_number, read_mat, whole_number

#: Fields every CLOTH3D ``info.mat`` has and :func:`read_info` / :func:`write_info` need.
REQUIRED_FIELDS = ("poses", "trans", "shape", "gender", "zrot", "outfit")
POSE_SIZE = 72  # 24 SMPL joints × 3 axis-angle components
#: ``gender`` value → SMPL model: CLOTH3D's starter kit reads ``'m' if gender else 'f'``.
GENDER_NAMES = ("female", "male")
#: MATLAB variable and struct field names (scipy's long_field_names allows 63 chars).
_MATLAB_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,62}")


def read_info(path: str | Path) -> dict[str, Any]:
    """Read a CLOTH3D ``info.mat`` into a dict with a leading frame axis.

    Args:
        path: the ``info.mat`` file.

    Returns:
        dict with ``poses (T, 72)``, ``trans (T, 3)``, ``shape (B,)`` (B = 10 in
        CLOTH3D), ``gender`` int, ``zrot`` float, ``outfit`` dict, and every other stored
        field (MATLAB structs as dicts, cell and struct arrays as lists, MATLAB scalars
        as Python numbers, strings as ``str``).

    Raises:
        Cloth3DError: missing or unreadable file, a required field missing, or a field
            of the wrong shape (e.g. poses and trans with different frame counts).
    """
    path = Path(path)
    if not path.is_file():
        raise Cloth3DError(f"{path}: info.mat not found")
    try:
        info = read_mat(path)
    except MatFileError as error:
        raise Cloth3DError(str(error)) from None
    try:
        return normalise_info(info, stored=True)
    except ValueError as error:
        raise Cloth3DError(f"{path}: {error}") from error


def normalise_info(info: Mapping[str, Any], stored: bool = False) -> dict[str, Any]:
    """Check the required fields and give them :func:`read_info`'s layout.

    Args:
        info: the fields.
        stored: True for CLOTH3D's on-disk layout (``poses (72, T)`` or ``(72,)``),
            False for ours (``poses (T, 72)`` or ``(72,)``); the two are never guessed
            from the shape, which is ambiguous when ``T`` is 72 (or 3 for trans).

    Raises:
        ValueError: a required field is missing or malformed.
    """
    missing = [field for field in REQUIRED_FIELDS if field not in info]
    if missing:
        raise ValueError(f"missing field(s) {', '.join(missing)} "
                         f"(CLOTH3D info.mat has {', '.join(REQUIRED_FIELDS)})")
    out = dict(info)
    out["poses"] = _frames_first(info["poses"], POSE_SIZE, "poses", stored)
    out["trans"] = _frames_first(info["trans"], 3, "trans", stored)
    if len(out["poses"]) != len(out["trans"]):
        raise ValueError(f"poses has {len(out['poses'])} frames but trans has "
                         f"{len(out['trans'])}")
    shape = finite_array(info["shape"], "shape")
    if shape.ndim > 1:
        raise ValueError(f"shape has shape {shape.shape}, expected (10,) betas")
    out["shape"] = np.atleast_1d(shape)
    out["gender"] = whole_number(info["gender"], "gender")
    out["zrot"] = finite_number(info["zrot"], "zrot")
    if not isinstance(info["outfit"], Mapping):
        raise ValueError(f"outfit is a {type(info['outfit']).__name__}, expected a struct "
                         f"with one field per garment")
    out["outfit"] = dict(info["outfit"])
    return out


def _frames_first(value: Any, size: int, name: str, stored: bool) -> np.ndarray:
    """``(size, T)`` (stored) or ``(T, size)`` (ours), or ``(size,)`` → ``(T, size)``."""
    array = finite_array(value, name)
    if array.shape == (size,):
        out = array[None, :]
    elif stored and array.ndim == 2 and array.shape[0] == size and array.shape[1] >= 1:
        out = array.T
    elif not stored and array.ndim == 2 and array.shape[1] == size and array.shape[0] >= 1:
        out = array
    else:
        expected = f"({size}, T) or ({size},)" if stored else f"(T, {size}) or ({size},)"
        raise ValueError(f"{name} has shape {array.shape}, expected {expected}")
    return np.ascontiguousarray(out)


def write_info(path: str | Path, info: Mapping[str, Any]) -> Path:
    """Write ``info`` as a CLOTH3D ``info.mat``, atomically.

    The layout is CLOTH3D's (``poses (72, T)``, ``trans (3, T)``, ``outfit`` and other
    dicts as nested structs), readable by :func:`read_info`, plain
    ``scipy.io.loadmat`` and MATLAB.

    Args:
        path: destination ``info.mat``.
        info: as returned by :func:`read_info` (``poses (T, 72)`` or ``(72,)``,
            ``trans (T, 3)`` or ``(3,)``, ``shape``, ``gender``, ``zrot``, ``outfit``)
            plus any extra fields: numbers, strings, numeric arrays, dicts (written as
            structs) and lists (numeric → arrays, otherwise cell arrays).

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        ValueError: a required field missing or malformed, a key that is not a valid
            MATLAB name (letter first, then letters, digits, ``_``; at most 63), or a
            value of a type MATLAB cannot hold (e.g. ``None``).

    Note:
        ``loadmat(squeeze_me=True)`` gives back a one-element list as its element and a
        bool as an int; such values do not round-trip exactly.
    """
    from scipy.io import savemat

    path = Path(path)
    try:
        normalised = normalise_info(info, stored=False)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from error
    record = {key: _to_matlab(value, key) for key, value in normalised.items()}
    for key in record:
        _check_name(key, key)
    # Back to CLOTH3D's on-disk layout: one column per frame.
    record["poses"] = np.ascontiguousarray(normalised["poses"].T)
    record["trans"] = np.ascontiguousarray(normalised["trans"].T)

    def write(stream: BinaryIO) -> None:
        savemat(stream, record, long_field_names=True)

    return atomic_write(path, write)


def _check_name(key: Any, where: str) -> None:
    if not isinstance(key, str) or not _MATLAB_NAME.fullmatch(key):
        raise ValueError(f"{where}: {key!r} is not a valid MATLAB field name (a letter, then "
                         f"letters, digits or '_', at most 63 characters)")


def _to_matlab(value: Any, where: str) -> Any:
    """Python value → something savemat writes faithfully; ``where`` names it in errors."""
    if isinstance(value, Mapping):
        out = {}
        for key, item in value.items():
            _check_name(key, f"{where}.{key}")
            out[key] = _to_matlab(item, f"{where}.{key}")
        return out
    if isinstance(value, (str, bool, int, float, np.generic)):
        return value
    if isinstance(value, np.ndarray):
        if value.dtype == object:
            return _cell(list(value.ravel()), where)
        if value.dtype.kind not in "biufcU":
            raise ValueError(f"{where}: arrays of dtype {value.dtype} cannot be stored")
        return value
    if isinstance(value, (list, tuple)):
        if value and all(isinstance(item, (bool, int, float, np.number)) for item in value):
            return np.asarray(value)
        # Strings and mixed items go in a cell array: a char matrix would pad strings.
        return _cell(list(value), where)
    raise ValueError(f"{where}: a {type(value).__name__} cannot be stored in a MAT file")


def _cell(items: list[Any], where: str) -> np.ndarray:
    cell = np.empty(len(items), dtype=object)
    for index, item in enumerate(items):
        cell[index] = _to_matlab(item, f"{where}[{index}]")
    return cell
