"""A garment coloured by attribution, as a PLY any mesh viewer opens."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gnngarment.attribution.colors import DEFAULT_COLORMAP, heat_colors, normalise_heat
from gnngarment.io.atomic import atomic_write_bytes


def write_attribution_ply(path: str | Path, pos: np.ndarray, faces: np.ndarray,
                          heat: np.ndarray, scale: str = "linear",
                          colormap: str = DEFAULT_COLORMAP) -> Path:
    """Write the garment with per-vertex colours from ``heat`` (binary PLY, atomically).

    The vertex order of ``pos`` is kept (trimesh with ``process=False``: no merging or
    reordering), so vertex ``i`` of the file is vertex ``i`` of the attribution. Besides
    RGBA, every vertex carries the raw heat twice as float properties: ``attribution``
    and ``quality`` (the name MeshLab reads as vertex quality, for its own colour maps).

    Shapes:
        pos ``(N, 3)`` (metres), faces ``(F, 3)``, heat ``(N,)``.

    Raises:
        ValueError: mismatched shapes or bad heat (see :func:`normalise_heat`).
    """
    import trimesh
    from trimesh.exchange.ply import export_ply

    pos = np.asarray(pos, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    heat = np.asarray(heat, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"pos must have shape (N, 3), got {pos.shape}")
    if heat.shape != (pos.shape[0],):
        raise ValueError(f"heat must have shape ({pos.shape[0]},), got {heat.shape}")
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"faces must have shape (F, 3), got {faces.shape}")
    colors = heat_colors(normalise_heat(heat, scale), colormap)
    mesh = trimesh.Trimesh(vertices=pos, faces=faces, vertex_colors=colors, process=False)
    mesh.vertex_attributes["attribution"] = heat.astype(np.float32)
    mesh.vertex_attributes["quality"] = heat.astype(np.float32)
    return atomic_write_bytes(path, export_ply(mesh, encoding="binary"))
