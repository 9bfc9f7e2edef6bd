"""The error raised for a CLOTH3D file or sequence folder that cannot be used."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from gnngarment.io.point_cache import PointCacheError


class Cloth3DError(ValueError):
    """A CLOTH3D file is missing, truncated or inconsistent; the message names the file.

    Messages read ``<path>: <problem>`` so a dataset build can log them as they are.
    """


class Cloth3DPointCacheError(Cloth3DError, PointCacheError):
    """A point cache that cannot be used; caught as either error type."""


@contextmanager
def point_cache_errors() -> Iterator[None]:
    """Re-raise :mod:`gnngarment.io.point_cache`'s :class:`PointCacheError` as a
    :class:`Cloth3DPointCacheError` with the same message (``<path>: <problem>``), so
    the CLOTH3D reader's callers catch every problem as a :class:`Cloth3DError`."""
    try:
        yield
    except Cloth3DError:
        raise
    except PointCacheError as error:
        raise Cloth3DPointCacheError(str(error)) from error
