"""One Wavefront OBJ per frame, vertices in the input's order (Blender: "Keep Vert Order").

Each file holds only ``v`` and ``f`` lines (no normals, UVs, groups or objects), so every
importer reads the vertices back in file order and a point cache or shape key made from
one frame lines up with any other. Coordinates are the library's world frame: metres,
**Z up**, the body facing −Y (import with "Up: Z, Forward: Y" in Blender to keep them).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from gnngarment.inference.export.atomic import atomic_write_bytes

#: Decimals written per coordinate: 1 µm, far below any garment detail.
DECIMALS = 6


def obj_text(pos: np.ndarray, faces: np.ndarray, header: str = "") -> str:
    """The OBJ text of one mesh: optional ``# header`` lines, ``v`` lines in order, then
    ``f`` lines (1-based).

    Shapes:
        pos ``(N, 3)``, faces ``(F, 3)`` 0-based.
    """
    comments = "".join(f"# {line}\n" for line in header.splitlines())
    return comments + _vertex_block(np.asarray(pos)) + _face_block(np.asarray(faces))


def write_obj(path: str | Path, pos: np.ndarray, faces: np.ndarray, header: str = "") -> Path:
    """Write one OBJ atomically (see :func:`obj_text`); the folder must exist."""
    _check(np.asarray(pos)[None], np.asarray(faces))
    return atomic_write_bytes(path, obj_text(pos, faces, header).encode("ascii"))


def frame_path(folder: str | Path, stem: str, number: int, digits: int = 4) -> Path:
    """``folder/<stem>_<number zero-padded>.obj``."""
    return Path(folder) / f"{stem}_{number:0{digits}d}.obj"


def write_obj_sequence(folder: str | Path, frames: np.ndarray, faces: np.ndarray,
                       stem: str = "garment", first_frame: int = 1,
                       progress: Callable[[int, int], None] | None = None) -> list[Path]:
    """Write ``folder/<stem>_0001.obj`` … one per frame, each atomically.

    Args:
        folder: created if missing.
        frames: ``(T, N, 3)`` positions, metres, in the order of the input mesh.
        faces: ``(F, 3)`` 0-based triangles (the same for every frame).
        stem: file name prefix.
        first_frame: number of the first file (1 matches Blender's first frame and the
            ``.pc2`` header written next to it).
        progress: called with (frames written, total).

    Returns:
        The paths, in frame order. Numbers are zero-padded to at least 4 digits (more if
        the sequence needs them), so a name sort is a frame sort.

    Raises:
        ValueError: wrong shapes, non-finite positions or out-of-range faces.
    """
    frames = np.asarray(frames)
    faces = np.asarray(faces)
    _check(frames, faces)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    digits = max(4, len(str(first_frame + len(frames) - 1)))
    face_block = _face_block(faces)
    paths = []
    for t, frame in enumerate(frames):
        path = frame_path(folder, stem, first_frame + t, digits)
        text = f"# {stem} frame {first_frame + t}\n" + _vertex_block(frame) + face_block
        paths.append(atomic_write_bytes(path, text.encode("ascii")))
        if progress is not None:
            progress(t + 1, len(frames))
    return paths


def _vertex_block(pos: np.ndarray) -> str:
    # One %-format over the whole frame is ~3× faster than numpy.savetxt.
    line = f"v %.{DECIMALS}f %.{DECIMALS}f %.{DECIMALS}f\n"
    return (line * len(pos)) % tuple(np.asarray(pos, dtype=np.float64).ravel().tolist())


def _face_block(faces: np.ndarray) -> str:
    return ("f %d %d %d\n" * len(faces)) % tuple((np.asarray(faces) + 1).ravel().tolist())


def _check(frames: np.ndarray, faces: np.ndarray) -> None:
    if frames.ndim != 3 or frames.shape[2] != 3 or frames.shape[1] == 0:
        raise ValueError(f"frames must be (T, N, 3) with N ≥ 1, got {frames.shape}")
    if not np.isfinite(frames).all():
        raise ValueError("frames contain NaN or inf")
    if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"faces must be (F, 3) integers, got {faces.shape} {faces.dtype}")
    if len(faces) and (faces.min() < 0 or faces.max() >= frames.shape[1]):
        raise ValueError(f"faces index [{faces.min()}, {faces.max()}] outside "
                         f"[0, {frames.shape[1] - 1}]")
