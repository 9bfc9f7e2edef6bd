"""PointCache2 files: CLOTH3D's ``.pc16`` (float16) and Blender/3ds Max ``.pc2`` (float32).

Layout (all little-endian)::

    offset  0  12 bytes  magic  b"POINTCACHE2\\0"
    offset 12  int32     version (1)
    offset 16  int32     n_points
    offset 20  float32   start_frame
    offset 24  float32   sample_rate
    offset 28  int32     n_samples
    offset 32  n_samples × n_points × 3 values, frame-major, xyz per point

``.pc2`` values are float32; CLOTH3D's ``.pc16`` is the same file with float16 values.
The extension is the only thing that says which, so a file whose size fits neither the
header nor its extension is rejected rather than reinterpreted.

Timing fields: ``start_frame`` is the frame number of the first sample and
``sample_rate`` the number of frames between samples (1 = every frame), as 3ds Max and
Blender's PC2 exporter write them. Blender's *Mesh Cache* modifier in its default
*Frame* time mode ignores both: it shows sample ``scene_frame × frame_scale −
modifier.frame_start`` (see ``docs/export.md``).
"""

from __future__ import annotations

import mmap
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import numpy as np

from gnngarment.io.atomic import atomic_write


class PointCacheError(ValueError):
    """A point cache file is missing, truncated or inconsistent; the message reads
    ``<path>: <problem>``."""


MAGIC = b"POINTCACHE2\0"
VERSION = 1
HEADER = struct.Struct("<12siiffi")  # magic, version, n_points, start_frame, sample_rate, n
#: Value type of each extension; both little-endian.
DTYPES = {".pc16": np.dtype("<f2"), ".pc2": np.dtype("<f4")}
#: Largest finite float16; beyond it a .pc16 would store inf.
FLOAT16_MAX = float(np.finfo(np.float16).max)


@dataclass(frozen=True)
class PointCacheHeader:
    """The 32-byte header of a point cache, plus the value type its extension implies.

    Attributes:
        path: the file.
        n_points: points per frame (the garment's vertex count).
        n_samples: number of frames ``T``.
        start_frame: first frame number (float in the format; CLOTH3D writes 0).
        sample_rate: frames per sample (CLOTH3D writes 1); not a frame rate in fps.
        dtype: ``float16`` for ``.pc16``, ``float32`` for ``.pc2``.
    """

    path: Path
    n_points: int
    n_samples: int
    start_frame: float
    sample_rate: float
    dtype: np.dtype

    @property
    def payload_bytes(self) -> int:
        """Bytes the header promises after itself: ``n_samples · n_points · 3 · itemsize``."""
        return self.n_samples * self.n_points * 3 * self.dtype.itemsize


def cache_dtype(path: str | Path, half: bool | None = None) -> np.dtype:
    """Value type of a point cache: from ``half`` if given, else from the extension.

    Raises:
        ValueError: unknown extension with ``half=None``, or ``half`` contradicting the
            extension (a float32 payload in a ``.pc16`` file would fool every reader).
    """
    path = Path(path)
    by_extension = DTYPES.get(path.suffix.lower())
    if half is None:
        if by_extension is None:
            raise ValueError(f"{path}: unknown point cache extension '{path.suffix}' "
                             f"(expected .pc16 or .pc2, or pass half=True/False)")
        return by_extension
    wanted = DTYPES[".pc16"] if half else DTYPES[".pc2"]
    if by_extension is not None and by_extension != wanted:
        raise ValueError(f"{path}: half={half} contradicts the extension '{path.suffix}' "
                         f"(.pc16 holds float16, .pc2 float32)")
    return wanted


def read_point_cache_header(path: str | Path, half: bool | None = None) -> PointCacheHeader:
    """Read and validate a point cache's header and size, without reading the payload.

    Args:
        path: ``.pc16`` or ``.pc2`` file.
        half: value type override for other extensions (True float16, False float32).

    Returns:
        The header; its ``payload_bytes`` equals the bytes after the header.

    Raises:
        PointCacheError: missing file, short header, wrong magic or version, negative counts,
            non-finite or non-positive sample rate, or a file size that does not match
            the header (truncated, or trailing data); the message names the file.
    """
    path = Path(path)
    try:
        dtype = cache_dtype(path, half)
    except ValueError as error:
        raise PointCacheError(str(error)) from error
    try:
        with open(path, "rb") as stream:
            raw = stream.read(HEADER.size)
            size = stream.seek(0, 2)
    except FileNotFoundError as error:
        raise PointCacheError(f"{path}: point cache not found") from error
    except OSError as error:
        raise PointCacheError(f"{path}: cannot read point cache ({error})") from error
    if len(raw) < HEADER.size:
        raise PointCacheError(f"{path}: file has {len(raw)} bytes, shorter than the "
                           f"{HEADER.size}-byte POINTCACHE2 header")
    magic, version, n_points, start_frame, sample_rate, n_samples = HEADER.unpack(raw)
    if magic != MAGIC:
        raise PointCacheError(f"{path}: wrong magic {magic!r}, expected {MAGIC!r} "
                           f"(not a PointCache2 file)")
    if version != VERSION:
        raise PointCacheError(f"{path}: unsupported PointCache2 version {version}, "
                           f"expected {VERSION}")
    if n_points < 0 or n_samples < 0:
        raise PointCacheError(f"{path}: negative counts in header (n_points={n_points}, "
                           f"n_samples={n_samples})")
    if not np.isfinite(sample_rate) or sample_rate <= 0 or not np.isfinite(start_frame):
        raise PointCacheError(f"{path}: invalid header timing (start_frame={start_frame}, "
                           f"sample_rate={sample_rate})")
    header = PointCacheHeader(path, n_points, n_samples, float(start_frame),
                              float(sample_rate), dtype)
    available = size - HEADER.size
    if available != header.payload_bytes:
        problem = "truncated" if available < header.payload_bytes else "trailing data"
        hint = ""
        if available == 2 * header.payload_bytes and dtype.itemsize == 2:
            hint = "; exactly twice the float16 size: a float32 .pc2 file named .pc16?"
        elif 2 * available == header.payload_bytes and dtype.itemsize == 4:
            hint = "; exactly half the float32 size: a float16 .pc16 file named .pc2?"
        raise PointCacheError(
            f"{path}: {problem}: header promises {n_samples} frames × {n_points} points × 3 "
            f"× {dtype.itemsize} bytes = {header.payload_bytes} bytes, file holds "
            f"{available} after the header{hint}")
    return header


def read_point_cache(path: str | Path, half: bool | None = None,
                     frames: slice | None = None) -> np.ndarray:
    """Read a ``.pc16``/``.pc2`` point cache.

    The payload is memory-mapped and converted in one vectorised step; with ``frames``
    only the requested frames are read from disk.

    Args:
        path: ``.pc16`` or ``.pc2`` file.
        half: value type override for other extensions.
        frames: optional slice over the ``T`` frames.

    Returns:
        ``(T, N, 3)`` float32 positions in the file's units (CLOTH3D: metres).

    Raises:
        PointCacheError: as :func:`read_point_cache_header`.
    """
    return read_payload(read_point_cache_header(path, half), frames)


def read_payload(header: PointCacheHeader, frames: slice | None = None) -> np.ndarray:
    """The ``(T, N, 3)`` float32 payload of a cache whose ``header`` was validated."""
    shape = (header.n_samples, header.n_points, 3)
    if header.payload_bytes == 0:  # mmap cannot map zero bytes
        return np.zeros(shape, dtype=np.float32)[frames or slice(None)]
    try:
        with open(header.path, "rb") as stream, \
                mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ) as mapped:
            if len(mapped) < HEADER.size + header.payload_bytes:
                raise PointCacheError(f"{header.path}: truncated since its header was checked")
            values = np.frombuffer(mapped, dtype=header.dtype, count=int(np.prod(shape)),
                                   offset=HEADER.size).reshape(shape)
            out = np.array(values[frames or slice(None)], dtype=np.float32)
            # The view must go before the map closes (an exported buffer blocks close()).
            del values
    except OSError as error:
        raise PointCacheError(
            f"{header.path}: cannot read point cache payload ({error})") from error
    return out


def write_point_cache(path: str | Path, positions: np.ndarray, start_frame: float = 0.0,
                      sample_rate: float = 1.0, half: bool | None = None) -> Path:
    """Write positions as a PointCache2 file, atomically.

    Args:
        path: destination; ``.pc16`` writes float16, ``.pc2`` float32.
        positions: ``(T, N, 3)`` finite positions (metres for CLOTH3D). float16 keeps
            about 3 significant digits (±1 mm near 2 m), as CLOTH3D's own files do.
        start_frame: header start frame (CLOTH3D: 0).
        sample_rate: header sample rate (CLOTH3D: 1), must be positive.
        half: force float16 (True) or float32 (False); default from the extension.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        ValueError: wrong shape, non-finite values, values beyond float16 range for a
            half file, bad timing values, or an extension that contradicts ``half``.
    """
    path = Path(path)
    dtype = cache_dtype(path, half)
    positions = np.asarray(positions)
    if positions.ndim != 3 or positions.shape[2] != 3:
        raise ValueError(f"{path}: positions have shape {positions.shape}, expected (T, N, 3)")
    if not np.isfinite(positions).all():
        raise ValueError(f"{path}: positions contain NaN or inf")
    if dtype.itemsize == 2 and positions.size and np.abs(positions).max() > FLOAT16_MAX:
        raise ValueError(f"{path}: |positions| up to {np.abs(positions).max():g} overflow "
                         f"float16 (max {FLOAT16_MAX:g}); write a .pc2 instead")
    if not (np.isfinite(sample_rate) and sample_rate > 0 and np.isfinite(start_frame)):
        raise ValueError(f"{path}: invalid timing (start_frame={start_frame}, "
                         f"sample_rate={sample_rate})")
    n_samples, n_points = positions.shape[:2]
    header = HEADER.pack(MAGIC, VERSION, n_points, start_frame, sample_rate, n_samples)
    payload = np.ascontiguousarray(positions, dtype=dtype)

    def write(stream: BinaryIO) -> None:
        stream.write(header)
        stream.write(payload)  # C-contiguous, so its buffer is the payload; no copy

    return atomic_write(path, write)
