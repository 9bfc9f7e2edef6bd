"""Wavefront OBJ text: the one OBJ writer of the library, and a cheap vertex count.

A file holds optional ``# comment`` lines, ``v`` lines in the given vertex order, the
``vt`` lines when texture coordinates are given, then 1-based triangle ``f`` lines
(``f v/vt`` corners with texture coordinates). No normals, groups or objects, so every
importer reads the vertices back in file order and nothing is welded or reordered.

Precision: every coordinate (``v`` and ``vt``) is written with
:data:`SIGNIFICANT_DIGITS` = 9 significant digits (``%.9g``), enough to give float32
values back exactly (about 1 nm near 1 m).

Reading an OBJ is :func:`gnngarment.geometry.load_mesh`'s job (its own small OBJ reader
keeps unreferenced vertices, see :mod:`gnngarment.geometry.mesh_io`).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from gnngarment.io.atomic import atomic_write_bytes

#: Significant digits written per coordinate: float32 values read back exactly.
SIGNIFICANT_DIGITS = 9
_NUMBER = f"%.{SIGNIFICANT_DIGITS}g"

# A vertex line as gnngarment's OBJ reader sees one: first word exactly "v".
_VERTEX_LINE = re.compile(rb"^[ \t]*v[ \t]", re.MULTILINE)


def vertex_lines(pos: np.ndarray) -> str:
    """``v x y z`` lines, one per row of ``pos (N, 3)``, in order."""
    # One %-format over the whole mesh is ~3× faster than numpy.savetxt (same text).
    line = f"v {_NUMBER} {_NUMBER} {_NUMBER}\n"
    return (line * len(pos)) % tuple(np.asarray(pos, dtype=np.float64).ravel().tolist())


def face_lines(faces: np.ndarray, uv: np.ndarray | None = None,
               uv_faces: np.ndarray | None = None) -> str:
    """1-based ``f`` lines of ``faces (F, 3)``; with ``uv (K, 2)`` and ``uv_faces (F, 3)``
    the ``vt`` lines first and ``f v/vt`` corners."""
    faces = np.asarray(faces).astype(np.int64)
    if uv is None:
        return ("f %d %d %d\n" * len(faces)) % tuple((faces + 1).ravel().tolist())
    texture = (f"vt {_NUMBER} {_NUMBER}\n" * len(uv)) % tuple(
        np.asarray(uv, dtype=np.float64).ravel().tolist())
    corners = np.stack([faces, np.asarray(uv_faces).astype(np.int64)], axis=-1) + 1  # (F, 3, 2)
    return texture + ("f %d/%d %d/%d %d/%d\n" * len(faces)) % tuple(corners.ravel().tolist())


def obj_text(pos: np.ndarray, faces: np.ndarray, header: str = "",
             uv: np.ndarray | None = None, uv_faces: np.ndarray | None = None) -> str:
    """The OBJ text of one mesh: a ``# `` line per line of ``header``, then
    :func:`vertex_lines` and :func:`face_lines`. Nothing is checked (see
    :func:`write_obj`).

    Shapes:
        pos ``(N, 3)``, faces ``(F, 3)`` 0-based; uv ``(K, 2)`` (OBJ convention) and
        uv_faces ``(F, 3)`` 0-based per-corner indices into it, or both ``None``.
    """
    comments = "".join(f"# {line}\n" for line in header.splitlines())
    return comments + vertex_lines(pos) + face_lines(faces, uv, uv_faces)


def write_obj(path: str | Path, pos: np.ndarray, faces: np.ndarray, header: str = "",
              uv: np.ndarray | None = None, uv_faces: np.ndarray | None = None) -> Path:
    """Write one mesh as OBJ (:func:`obj_text`), atomically. Vertex order is kept,
    nothing is welded.

    Args:
        path: destination; missing parent folders are created.
        pos: ``(N, 3)`` positions (metres).
        faces: ``(F, 3)`` 0-based triangles.
        header: comment lines at the top (none by default).
        uv, uv_faces: texture coordinates ``(K, 2)`` and per-corner indices ``(F, 3)``,
            both or neither.

    Returns:
        ``path`` as a :class:`~pathlib.Path`.

    Raises:
        ValueError: wrong shapes, non-finite positions, face indices out of range, or
            inconsistent texture coordinates; the message names the file.
    """
    path = Path(path)
    pos = np.asarray(pos, dtype=np.float64)
    faces = np.asarray(faces)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"{path}: pos has shape {pos.shape}, expected (N, 3)")
    if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"{path}: faces have shape {faces.shape} and dtype {faces.dtype}, "
                         f"expected (F, 3) integers")
    if not np.isfinite(pos).all():
        raise ValueError(f"{path}: pos contains NaN or inf")
    if faces.size and (faces.min() < 0 or faces.max() >= len(pos)):
        raise ValueError(f"{path}: face indices span [{faces.min()}, {faces.max()}], "
                         f"outside [0, {len(pos) - 1}]")
    if (uv is None) != (uv_faces is None):
        raise ValueError(f"{path}: uv and uv_faces must be given together (or both None)")
    if uv is not None:
        try:
            check_texture_coordinates(uv, uv_faces, len(faces))
        except ValueError as error:
            raise ValueError(f"{path}: {error}") from error
    return atomic_write_bytes(path, obj_text(pos, faces, header, uv, uv_faces).encode("ascii"))


def check_texture_coordinates(uv: np.ndarray, uv_faces: np.ndarray, num_faces: int) -> None:
    """Raise a ``ValueError`` unless ``uv (K, 2)`` is finite and ``uv_faces (F, 3)``
    holds integer indices into it for ``num_faces`` triangles (OBJ's ``vt`` table and
    ``f v/vt`` corners; see :mod:`gnngarment.geometry.texture_coordinates`)."""
    uv = np.asarray(uv)
    uv_faces = np.asarray(uv_faces)
    if uv.ndim != 2 or uv.shape[1] != 2 or len(uv) == 0:
        raise ValueError(f"uv must be (K, 2) with K ≥ 1, got {uv.shape}")
    if not np.issubdtype(uv.dtype, np.floating) or not np.isfinite(uv).all():
        raise ValueError(f"uv must hold finite floats, got {uv.dtype}")
    if uv_faces.shape != (num_faces, 3):
        raise ValueError(f"uv_faces must be ({num_faces}, 3) like faces, got {uv_faces.shape}")
    if not np.issubdtype(uv_faces.dtype, np.integer):
        raise ValueError(f"uv_faces must hold integers, got {uv_faces.dtype}")
    if num_faces and (uv_faces.min() < 0 or uv_faces.max() >= len(uv)):
        raise ValueError(f"uv_faces indices span [{uv_faces.min()}, {uv_faces.max()}], "
                         f"outside [0, {len(uv) - 1}]")


def count_obj_vertices(path: str | Path) -> int:
    """Number of ``v`` lines in an OBJ, without parsing numbers (cheap dataset scans).

    Raises:
        OSError: the file cannot be read.
    """
    return len(_VERTEX_LINE.findall(Path(path).read_bytes()))
