"""PointCache2 files for CLOTH3D: the library's reader/writer with CLOTH3D's error type.

The implementation lives in :mod:`gnngarment.inference.export.point_cache` (the library
exports ``.pc2`` files and must not import ``data_prep``). Here its readers raise
:class:`Cloth3DPointCacheError`, which is both a :class:`Cloth3DError` (what the CLOTH3D
reader's callers catch) and the library's :class:`PointCacheError`.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from data_prep.cloth3d.errors import Cloth3DError
from gnngarment.inference.export import point_cache as _library
from gnngarment.inference.export.point_cache import (
    DTYPES,
    FLOAT16_MAX,
    HEADER,
    MAGIC,
    VERSION,
    PointCacheError,
    PointCacheHeader,
    cache_dtype,
    write_point_cache,
)

__all__ = [
    "DTYPES", "FLOAT16_MAX", "HEADER", "MAGIC", "VERSION", "Cloth3DPointCacheError",
    "PointCacheError", "PointCacheHeader", "cache_dtype", "read_payload", "read_point_cache",
    "read_point_cache_header", "write_point_cache",
]


class Cloth3DPointCacheError(Cloth3DError, PointCacheError):
    """A point cache that cannot be used; caught as either error type."""


@contextmanager
def _as_cloth3d_error() -> Iterator[None]:
    try:
        yield
    except Cloth3DError:
        raise
    except PointCacheError as error:
        raise Cloth3DPointCacheError(str(error)) from error


def read_point_cache_header(path: str | Path, half: bool | None = None) -> PointCacheHeader:
    """:func:`gnngarment.inference.export.point_cache.read_point_cache_header`.

    Raises:
        Cloth3DPointCacheError: as the library function (message ``<path>: <problem>``).
    """
    with _as_cloth3d_error():
        return _library.read_point_cache_header(path, half)


def read_payload(header: PointCacheHeader, frames: slice | None = None) -> np.ndarray:
    """The ``(T, N, 3)`` float32 payload of a cache whose ``header`` was validated."""
    with _as_cloth3d_error():
        return _library.read_payload(header, frames)


def read_point_cache(path: str | Path, half: bool | None = None,
                     frames: slice | None = None) -> np.ndarray:
    """:func:`gnngarment.inference.export.point_cache.read_point_cache`: ``(T, N, 3)``
    float32 positions.

    Raises:
        Cloth3DPointCacheError: as the library function.
    """
    return read_payload(read_point_cache_header(path, half), frames)
