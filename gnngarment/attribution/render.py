"""PNG heatmaps of attributions on the garment (matplotlib, headless)."""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from gnngarment.attribution.colors import (
    DEFAULT_COLORMAP,
    LOG_DECADES,
    heat_colors,
    normalise_heat,
)
from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.mesh_drawing import DrawnMesh, draw_meshes, project

#: ``(elevation, azimuth)`` in degrees of the default views of a Z-up garment
#: (:mod:`gnngarment.mesh_drawing`'s convention): front (camera on −Y, the body's
#: front) and back.
DEFAULT_VIEWS: tuple[tuple[float, float], ...] = ((12.0, 0.0), (12.0, 180.0))
VIEW_NAMES = {(12.0, 0.0): "front", (12.0, 180.0): "back"}

#: Brightness of a heatmap face turned away from the light: high, so that shading shows
#: the folds without changing the colour map's reading much.
HEAT_AMBIENT = 0.55


def render_attribution(path: str | Path, pos: np.ndarray, faces: np.ndarray, heat: np.ndarray,
                       *, targets: Sequence[int] | np.ndarray | None = None,
                       title: str | None = None,
                       views: Sequence[tuple[float, float]] = DEFAULT_VIEWS,
                       scale: str = "linear", colormap: str = DEFAULT_COLORMAP,
                       dpi: int = 110) -> Path:
    """Render the garment coloured by ``heat`` from each of ``views``, side by side,
    with a colour bar and the target vertices marked; write a PNG atomically.

    Colours are relative to the maximum heat (see :func:`normalise_heat`).

    Shapes:
        pos ``(N, 3)`` (metres, Z up), faces ``(F, 3)``, heat ``(N,)``, targets ``(K,)``.
    """
    return render_comparison(path, pos, faces, [heat], [title or ""], targets=targets,
                             views=views, scale=scale, colormap=colormap, dpi=dpi)


def render_comparison(path: str | Path, pos: np.ndarray, faces: np.ndarray,
                      heats: Sequence[np.ndarray], titles: Sequence[str], *,
                      targets: Sequence[int] | np.ndarray | None = None,
                      views: Sequence[tuple[float, float]] = DEFAULT_VIEWS,
                      scale: str = "linear", colormap: str = DEFAULT_COLORMAP,
                      suptitle: str | None = None, dpi: int = 110) -> Path:
    """Several heats on one garment (e.g. the same target under two models): one column
    per heat, one row per view (one row of views for a single heat), one shared colour
    bar. Each heat is normalised to its own maximum, so the pictures compare the
    *shape* of the fields.

    Raises:
        ValueError: mismatched shapes or counts, bad heat, unknown scale.
    """
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    pos = np.asarray(pos, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if pos.ndim != 2 or pos.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"pos must be (N, 3) and faces (F, 3), got {pos.shape} and {faces.shape}")
    if len(heats) == 0 or len(heats) != len(titles):
        raise ValueError(f"need one title per heat, got {len(heats)} heats, {len(titles)} titles")
    values = []
    for heat in heats:
        heat = np.asarray(heat, dtype=np.float64)
        if heat.shape != (pos.shape[0],):
            raise ValueError(f"heat must have shape ({pos.shape[0]},), got {heat.shape}")
        values.append(normalise_heat(heat, scale))
    marked = None if targets is None else np.atleast_1d(np.asarray(targets, dtype=np.int64))
    if marked is not None and marked.size and (marked.min() < 0 or marked.max() >= len(pos)):
        raise ValueError(f"targets must be vertex indices in 0..{len(pos) - 1}")

    single = len(heats) == 1
    rows, cols = (1, len(views)) if single else (len(views), len(heats))
    figure = Figure(figsize=(3.2 * cols + 1.2, 3.6 * rows + 0.4 + (0.5 if suptitle else 0.0)))
    for k, value in enumerate(values):
        for v, (elevation, azimuth) in enumerate(views):
            index = v if single else v * cols + k
            axes = figure.add_subplot(rows, cols, index + 1)
            _draw(axes, pos, faces, value, colormap, elevation, azimuth, marked)
            view = VIEW_NAMES.get((elevation, azimuth), f"elev {elevation:g}, azim {azimuth:g}")
            heading = f"{titles[k]}\n{view}" if titles[k] and (single or v == 0) else view
            axes.set_title(heading, fontsize=9)
    norm = Normalize(0.0, 1.0)
    figure.subplots_adjust(left=0.0, right=0.84, bottom=0.02, top=0.88 if suptitle else 0.92,
                           wspace=0.0, hspace=0.08)
    bar = figure.colorbar(ScalarMappable(norm=norm, cmap=colormap),
                          cax=figure.add_axes((0.86, 0.18, 0.02, 0.64)))
    if scale == "log":
        ticks = np.linspace(0.0, 1.0, int(LOG_DECADES) + 1)
        bar.set_ticks(ticks, labels=[f"{10 ** ((t - 1) * LOG_DECADES):.0e}" for t in ticks])
    bar.set_label("attribution / maximum" + (" (log)" if scale == "log" else ""))
    if suptitle:
        figure.suptitle(suptitle, fontsize=10)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    return atomic_write_bytes(path, buffer.getvalue())


def _draw(axes, pos: np.ndarray, faces: np.ndarray, value: np.ndarray, colormap: str,
          elevation: float, azimuth: float, marked: np.ndarray | None) -> None:
    colors = heat_colors(value[faces].mean(axis=1), colormap)[:, :3].astype(np.float64) / 255.0
    draw_meshes(axes, [DrawnMesh(pos, faces, colors, ambient=HEAT_AMBIENT)], azimuth,
                elevation)
    if marked is not None and marked.size:
        # Drawn over the mesh so the mark always shows. A ring, so the heat under it
        # stays visible; faint and thin where the vertex is behind cloth, so the two
        # views do not both seem to face the target.
        camera = project(pos, azimuth, elevation)
        visible = _visible(camera, marked)
        size = 90 if marked.size == 1 else 14
        for show, width, alpha in ((visible, 2.0, 1.0), (~visible, 1.0, 0.5)):
            if show.any():
                axes.scatter(*camera[marked[show], :2].T, s=size, facecolors="none",
                             edgecolors="#00e5ff", linewidths=width, alpha=alpha, zorder=10)


def _visible(camera: np.ndarray, marked: np.ndarray) -> np.ndarray:
    """``(K,)`` whether each marked vertex is in front: no vertex that projects near it
    on the screen (within 3% of the garment's size) is more than 2% closer to the
    camera. Orientation-free, so it works for open garments with either winding.

    Shapes:
        camera ``(N, 3)`` (screen X, screen Y, depth towards the viewer), marked ``(K,)``.
    """
    size = float(np.ptp(camera, axis=0).max()) or 1.0
    depth, screen = camera[:, 2], camera[:, :2]
    visible = np.empty(len(marked), dtype=bool)
    for k, vertex in enumerate(marked):
        near = np.linalg.norm(screen - screen[vertex], axis=1) < 0.03 * size
        visible[k] = depth[near].max() <= depth[vertex] + 0.02 * size
    return visible
