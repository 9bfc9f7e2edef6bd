"""One Wavefront OBJ per frame, vertices in the input's order (Blender: "Keep Vert Order").

Each file holds ``v`` and ``f`` lines and, when the input garment had texture
coordinates, its ``vt`` lines with ``f v/vt`` corners exactly as the input indexed them
(seams included: UVs are per face corner, so the ``v`` lines stay the input's vertices).
No normals, groups or objects, so every importer reads the vertices back in file order
and a point cache or shape key made from one frame lines up with any other. Coordinates
are the library's world frame: metres, **Z up**, the body facing −Y (import with "Up: Z,
Forward: Y" in Blender to keep them).

The lines are :mod:`gnngarment.io.obj`'s (the library's one OBJ writer: 9 significant
digits per coordinate; a single OBJ is :func:`gnngarment.io.obj.write_obj`); this module
names the frames' files and checks the whole sequence before writing any of them.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.io.obj import check_texture_coordinates, face_lines, vertex_lines


def frame_path(folder: str | Path, stem: str, number: int, digits: int = 4) -> Path:
    """``folder/<stem>_<number zero-padded>.obj``."""
    return Path(folder) / f"{stem}_{number:0{digits}d}.obj"


def write_obj_sequence(folder: str | Path, frames: np.ndarray, faces: np.ndarray,
                       stem: str = "garment", first_frame: int = 0,
                       progress: Callable[[int, int], None] | None = None,
                       uv: np.ndarray | None = None,
                       uv_faces: np.ndarray | None = None) -> list[Path]:
    """Write ``folder/<stem>_0000.obj`` … one per frame, each atomically.

    Args:
        folder: created if missing.
        frames: ``(T, N, 3)`` positions, metres, in the order of the input mesh.
        faces: ``(F, 3)`` 0-based triangles (the same for every frame).
        stem: file name prefix.
        first_frame: number of the first file (the frame number ``frames[0]`` has in
            every export: the ``.pc2`` header, the glb's time × fps).
        progress: called with (frames written, total).
        uv, uv_faces: the input's texture coordinates ``(K, 2)`` and per-corner indices
            ``(F, 3)``, written as ``vt`` lines and ``f v/vt`` corners in every file.

    Returns:
        The paths, in frame order. Numbers are zero-padded to at least 4 digits (more if
        the sequence needs them), so a name sort is a frame sort.

    Raises:
        ValueError: wrong shapes, non-finite positions or out-of-range faces (or UVs).
    """
    frames = np.asarray(frames)
    faces = np.asarray(faces)
    _check(frames, faces, uv, uv_faces)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    digits = max(4, len(str(first_frame + len(frames) - 1)))
    face_block = face_lines(faces, uv, uv_faces)  # the same in every frame
    paths = []
    for t, frame in enumerate(frames):
        path = frame_path(folder, stem, first_frame + t, digits)
        text = f"# {stem} frame {first_frame + t}\n" + vertex_lines(frame) + face_block
        paths.append(atomic_write_bytes(path, text.encode("ascii")))
        if progress is not None:
            progress(t + 1, len(frames))
    return paths


def _check(frames: np.ndarray, faces: np.ndarray, uv: np.ndarray | None = None,
           uv_faces: np.ndarray | None = None) -> None:
    if frames.ndim != 3 or frames.shape[2] != 3 or frames.shape[1] == 0:
        raise ValueError(f"frames must be (T, N, 3) with N ≥ 1, got {frames.shape}")
    if not np.isfinite(frames).all():
        raise ValueError("frames contain NaN or inf")
    if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"faces must be (F, 3) integers, got {faces.shape} {faces.dtype}")
    if len(faces) and (faces.min() < 0 or faces.max() >= frames.shape[1]):
        raise ValueError(f"faces index [{faces.min()}, {faces.max()}] outside "
                         f"[0, {frames.shape[1] - 1}]")
    if (uv is None) != (uv_faces is None):
        raise ValueError("uv and uv_faces must be given together (or both None)")
    if uv is not None:
        check_texture_coordinates(uv, uv_faces, len(faces))
