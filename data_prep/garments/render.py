"""Pictures of garments: shaded, depth-sorted triangles on a matplotlib axis (Agg).

A hand-rolled projection (painter's algorithm over a ``PolyCollection``) instead of
``mplot3d``: it is faster, and it draws the body and the garment in one depth order,
so the garment correctly hides the body behind it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gnngarment.geometry.normals import face_normals


def view_rotation(azimuth_deg: float = 20.0, elevation_deg: float = 10.0) -> np.ndarray:
    """``(3, 3)`` world → camera rotation: camera X right, Y up, Z towards the viewer.
    Azimuth 0 looks at the body's front (from −Y); positive turns towards its left side."""
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    # Looking along +Y at the front: right = +X, up = +Z, towards viewer = −Y.
    base = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    turn = np.array([[np.cos(az), -np.sin(az), 0], [np.sin(az), np.cos(az), 0], [0, 0, 1]])
    tilt = np.array([[1, 0, 0], [0, np.cos(el), np.sin(el)], [0, -np.sin(el), np.cos(el)]])
    return tilt @ base @ turn


def draw_meshes(ax: Any, meshes: list[tuple[np.ndarray, np.ndarray, tuple[float, float, float],
                                             float]],
                azimuth_deg: float = 20.0, elevation_deg: float = 10.0,
                edge_color: Any = None, edge_width: float = 0.0, flat: tuple[int, ...] = ()
                ) -> None:
    """Draw triangle meshes on a 2D matplotlib axis.

    Args:
        ax: a matplotlib ``Axes``.
        meshes: ``(pos (N, 3), faces (F, 3), rgb, alpha)`` per mesh; each face is lit by
            a light over the viewer's shoulder (two-sided, so the inside of an opening
            shows darker).
        edge_color, edge_width: optional wireframe over the first mesh only.
        flat: indices of meshes drawn unlit, in one colour (a silhouette).
    """
    from matplotlib.collections import PolyCollection

    rotation = view_rotation(azimuth_deg, elevation_deg)
    polygons, colors, depths, edges = [], [], [], []
    light = np.array([0.3, 0.5, 1.0])
    light /= np.linalg.norm(light)
    for index, (pos, faces, rgb, alpha) in enumerate(meshes):
        camera = np.asarray(pos) @ rotation.T
        corners = camera[np.asarray(faces)]
        normal = face_normals(camera, faces)
        facing = normal[:, 2] >= 0
        shade = np.abs(normal @ light)
        shade = np.where(facing, 0.35 + 0.65 * shade, 0.2 + 0.35 * shade)
        if index in flat:
            shade = np.ones_like(shade)
        color = np.clip(np.asarray(rgb)[None, :] * shade[:, None], 0, 1)
        polygons.append(corners[:, :, :2])
        colors.append(np.concatenate([color, np.full((len(color), 1), alpha)], axis=1))
        depths.append(corners[:, :, 2].mean(axis=1))
        edges.append(np.full(len(faces), index == 0))
    polygons_all = np.concatenate(polygons)
    order = np.argsort(np.concatenate(depths))
    face_colors = np.concatenate(colors)[order]
    collection = PolyCollection(polygons_all[order], facecolors=face_colors,
                                edgecolors=face_colors if edge_color is None else "none",
                                linewidths=0.2 if edge_color is None else 0.0)
    ax.add_collection(collection)
    if edge_color is not None and edge_width > 0:
        wire = polygons_all[order][np.concatenate(edges)[order]]
        ax.add_collection(PolyCollection(wire, facecolors="none", edgecolors=edge_color,
                                         linewidths=edge_width))
    lo, hi = polygons_all.reshape(-1, 2).min(axis=0), polygons_all.reshape(-1, 2).max(axis=0)
    pad = 0.03 * float((hi - lo).max())
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_axis_off()
