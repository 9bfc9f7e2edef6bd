"""A quick-look animated GIF of the garment on the body: an orthographic camera, Lambert
shading (two-sided for the cloth) and a small z-buffer rasteriser in numpy, so it runs
headless with no display, OpenGL or matplotlib backend.

Fast by construction: the body is decimated once by vertex clustering (the same clusters
for every frame), back-facing body triangles are culled, all triangles of a frame are
rasterised in one vectorised pass, and the rasteriser outputs palette indices (a shade
ramp per material) so the GIF needs no colour quantisation.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gnngarment.geometry.normals import face_normals, vertex_normals
from gnngarment.inference.export.validation import check_animation
from gnngarment.io.atomic import atomic_write_bytes

if TYPE_CHECKING:
    from gnngarment.inference.animate import Animation

#: Garment colours: a single garment is the first; an outfit's garments alternate, so
#: each garment stands out from the one it is worn over.
GARMENT_RGB = (np.array([0.85, 0.33, 0.25]), np.array([0.25, 0.47, 0.80]))
BODY_RGB = np.array([0.72, 0.72, 0.72])
#: Shade levels per material in the 256-colour palette (two garment colours, the body;
#: the last index is the white background).
LEVELS = 85
BODY_OFFSET = len(GARMENT_RGB) * LEVELS
BACKGROUND = BODY_OFFSET + LEVELS
AMBIENT = 0.3


def palette() -> np.ndarray:
    """``(256, 3)`` uint8: the shades of each garment colour (0..84, 85..169), of the body
    (170..254), then white (255)."""
    shades = AMBIENT + (1 - AMBIENT) * np.arange(LEVELS) / (LEVELS - 1)
    colours = np.concatenate([shades[:, None] * rgb for rgb in (*GARMENT_RGB, BODY_RGB)]
                             + [np.ones((256 - BACKGROUND, 3))])
    return np.round(255 * colours).astype(np.uint8)


def preview_frames(num_frames: int, fps: float, max_frames: int = 48) -> tuple[np.ndarray, float]:
    """Every ``k``-th frame so at most ``max_frames`` are rendered, and the GIF frame
    duration in seconds that keeps real-time speed (``k / fps``)."""
    stride = max(1, -(-num_frames // max_frames))
    return np.arange(0, num_frames, stride), stride / fps


def cluster_decimation(frames: np.ndarray, faces: np.ndarray, max_faces: int = 4000
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Vertex-clustering decimation that stays valid over a whole sequence.

    Vertices share a cluster when they fall in the same grid cell in the first, middle
    and last frames (so an arm resting on the torso in one frame is not welded to it),
    and the cell grows until at most ``max_faces`` triangles survive.

    Shapes:
        frames ``(T, N, 3)``, faces ``(F, 3)`` → ``labels (N,)`` cluster of each vertex
        and ``faces (F', 3)`` over the clusters.
    """
    frames = np.asarray(frames, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if len(faces) <= max_faces:
        return np.arange(frames.shape[1]), faces
    keys_from = frames[np.unique([0, len(frames) // 2, len(frames) - 1])]
    extent = np.ptp(frames[0], axis=0).max()
    cell = extent / 80.0
    for _ in range(30):
        cells = np.floor(keys_from / cell).astype(np.int64)  # (K, N, 3)
        keys = np.ascontiguousarray(cells.transpose(1, 0, 2).reshape(frames.shape[1], -1))
        _, labels = np.unique(keys, axis=0, return_inverse=True)
        labels = labels.ravel()
        mapped = labels[faces]
        keep = ((mapped[:, 0] != mapped[:, 1]) & (mapped[:, 1] != mapped[:, 2])
                & (mapped[:, 0] != mapped[:, 2]))
        mapped = mapped[keep]
        # Duplicates with the same winding collapse; opposite windings both stay.
        rolled = np.stack([np.roll(mapped, -k, axis=1) for k in range(3)])
        canonical = rolled[np.argmin(rolled[:, :, 0], axis=0), np.arange(len(mapped))]
        mapped = np.unique(canonical, axis=0)
        if len(mapped) <= max_faces:
            return labels, mapped
        cell *= 1.25
    return labels, mapped


def render_preview(animation: Animation, path: str | Path, *, size: int = 288,
                   max_frames: int = 48, include_body: bool = True, max_body_faces: int = 4000,
                   azimuth: float = 30.0, elevation: float = 12.0, supersample: int = 1,
                   progress: Callable[[int, int], None] | None = None,
                   garment_faces: Sequence[int] | None = None) -> Path:
    """Write an animated GIF (or MP4, if ``imageio-ffmpeg`` is installed) of the garment
    (coloured) on the body (grey), atomically.

    Args:
        animation: ``posed (T, N, 3)``, ``faces``; ``body_vertices (T, N_b, 3)``,
            ``body_faces`` when ``include_body``.
        path: ``.gif`` (or ``.mp4``).
        size: image height and width in pixels.
        max_frames: render every ``k``-th frame so at most this many are drawn; the GIF
            plays at the animation's real speed.
        include_body: draw the body too.
        max_body_faces: the body is decimated to about this many triangles.
        azimuth, elevation: camera direction in degrees; azimuth 0 looks at the body's
            front (it faces −Y), positive turns the camera towards the body's left (+X).
        supersample: anti-aliasing factor (rendered at ``size × supersample``, averaged;
            2 looks smoother and costs ~4× the time).
        progress: called with (frames rendered, total).
        garment_faces: for an outfit drawn as one animation, the number of faces of each
            garment in ``faces`` order; consecutive garments get alternating colours.

    Returns:
        ``path``.
    """
    check_animation(animation, body=include_body)
    path = Path(path)
    if path.suffix.lower() not in (".gif", ".mp4"):
        raise ValueError(f"{path}: preview must be .gif or .mp4")
    chosen, duration = preview_frames(len(animation.posed), animation.fps, max_frames)
    # (frames, faces, palette offset of the material, two-sided)
    posed = np.asarray(animation.posed, dtype=np.float64)[chosen]
    faces = np.asarray(animation.faces, dtype=np.int64)
    counts = [len(faces)] if garment_faces is None else [int(c) for c in garment_faces]
    if sum(counts) != len(faces) or min(counts) < 0:
        raise ValueError(f"garment_faces {counts} must add up to the {len(faces)} faces")
    starts = np.cumsum([0, *counts])
    meshes = [(posed, faces[starts[k]:starts[k + 1]], (k % len(GARMENT_RGB)) * LEVELS, True)
              for k in range(len(counts)) if counts[k]]
    if include_body:
        body_all = np.asarray(animation.body_vertices, dtype=np.float64)[chosen]
        labels, body_faces = cluster_decimation(body_all, animation.body_faces, max_body_faces)
        counts = np.bincount(labels)
        body = np.stack([np.stack([np.bincount(labels, frame[:, a]) / counts
                                   for a in range(3)], axis=1) for frame in body_all])
        meshes.append((body, body_faces, BODY_OFFSET, False))
    right, up, forward = _camera(azimuth, elevation)
    light = _normalised(-forward + 0.6 * up - 0.4 * right)
    # Fixed framing from everything drawn, over all frames.
    screen = np.concatenate([m[0].reshape(-1, 3) for m in meshes]) @ np.stack([right, up], 1)
    low, high = screen.min(axis=0), screen.max(axis=0)
    pixels = size * supersample
    scale = pixels / (1.1 * (high - low).max())
    origin = (low + high) / 2

    indices = []
    for k in range(len(chosen)):
        triangles, depths, levels = [], [], []
        for frames, faces, offset, two_sided in meshes:
            vertices = frames[k]
            normals = vertex_normals(vertices, faces)
            facing = face_normals(vertices, faces) @ -forward
            if two_sided:
                keep = np.ones(len(faces), dtype=bool)
                lit = np.abs(normals @ light)[faces] * np.where(facing < 0, 0.8, 1.0)[:, None]
            else:
                keep = facing > 0
                lit = np.clip(normals @ light, 0.0, 1.0)[faces]
            corners = vertices[faces[keep]]  # (F, 3, 3)
            x = (corners @ right - origin[0]) * scale + pixels / 2
            y = pixels / 2 - (corners @ up - origin[1]) * scale
            triangles.append(np.stack([x, y], axis=-1))
            depths.append(corners @ forward)
            levels.append(offset + lit[keep] * (LEVELS - 1))  # palette index, per corner
        level = rasterize(np.concatenate(triangles), np.concatenate(depths),
                          np.concatenate(levels), pixels, background=BACKGROUND)
        indices.append(np.round(level).astype(np.uint8))
        if progress is not None:
            progress(k + 1, len(chosen))
    if supersample > 1 or path.suffix.lower() == ".mp4":
        colours = palette()
        images = [colours[index].reshape(size, supersample, size, supersample, 3)
                  .mean(axis=(1, 3)).round().astype(np.uint8) for index in indices]
        return _write_rgb(path, images, duration)
    return _write_indexed_gif(path, indices, duration)


def rasterize(triangles: np.ndarray, depths: np.ndarray, values: np.ndarray, size: int,
              background: float = 0.0, chunk: int = 2_000_000) -> np.ndarray:
    """Z-buffered rasterisation of screen-space triangles with a per-corner value
    interpolated across each triangle, in numpy.

    The pixel bounding boxes of many triangles are enumerated at once (at most ``chunk``
    candidate pixels per pass, so huge triangles cannot exhaust memory), pixel centres
    are tested with barycentric coordinates, and the nearest candidate of each pixel wins.

    Shapes:
        triangles ``(F, 3, 2)`` pixel coordinates (x right, y down), depths ``(F, 3)``
        (larger is farther), values ``(F, 3)`` → ``(size, size)`` float32 image.
    """
    triangles = np.asarray(triangles, dtype=np.float32)
    image = np.full(size * size, background, dtype=np.float32)
    nearest = np.full(size * size, np.inf, dtype=np.float32)
    low = np.clip(np.floor(triangles.min(axis=1)), 0, size - 1).astype(np.int32)
    high = np.clip(np.ceil(triangles.max(axis=1)), 0, size - 1).astype(np.int32)
    width = high[:, 0] - low[:, 0] + 1
    edges = triangles[:, 1:] - triangles[:, :1]  # (F, 2, 2)
    area = edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0]
    visible = ((np.abs(area) > 1e-6) & (triangles.max(axis=1) >= 0).all(axis=1)
               & (triangles.min(axis=1) <= size).all(axis=1))
    counts = np.where(visible, width * (high[:, 1] - low[:, 1] + 1), 0)
    ends = np.cumsum(counts)
    per_face = (low, width, triangles[:, 0], edges, np.where(visible, area, 1.0),
                np.asarray(depths, np.float32), np.asarray(values, np.float32))
    start = 0
    while start < len(triangles):
        # Triangles whose candidates fit in this pass (at least one).
        stop = max(start + 1, int(np.searchsorted(ends, ends[start] - counts[start] + chunk,
                                                  side="right")))
        _rasterize_pass(slice(start, stop), counts, per_face, size, image, nearest)
        start = stop
    return image.reshape(size, size)


def _rasterize_pass(faces: slice, counts: np.ndarray, per_face: tuple, size: int,
                    image: np.ndarray, nearest: np.ndarray) -> None:
    low, width, origin, edges, area, depths, values = (a[faces] for a in per_face)
    count = counts[faces]
    total = int(count.sum())
    if total == 0:
        return
    face = np.repeat(np.arange(len(count), dtype=np.int32), count)
    local = np.arange(total, dtype=np.int32) - np.repeat(
        (np.cumsum(count) - count).astype(np.int32), count)
    row, column = np.divmod(local, width[face])
    px, py = low[face, 0] + column, low[face, 1] + row
    # Barycentric coordinates of the pixel centre.
    dx = px + np.float32(0.5) - origin[face, 0]
    dy = py + np.float32(0.5) - origin[face, 1]
    e = edges[face]
    u = (dx * e[:, 1, 1] - dy * e[:, 1, 0]) / area[face]
    v = (e[:, 0, 0] * dy - e[:, 0, 1] * dx) / area[face]
    w = 1 - u - v
    inside = (u >= -1e-6) & (v >= -1e-6) & (w >= -1e-6)
    face, u, v, w = face[inside], u[inside], v[inside], w[inside]
    pixel = py[inside] * size + px[inside]
    # float32 like the buffer, or a candidate could miss its own rounded minimum.
    depth = (w * depths[face, 0] + u * depths[face, 1] + v * depths[face, 2]).astype(
        nearest.dtype)
    # Z-buffer: the nearest depth per pixel, then the candidates that reach it.
    np.minimum.at(nearest, pixel, depth)
    won = depth <= nearest[pixel]
    f = face[won]
    image[pixel[won]] = (w[won] * values[f, 0] + u[won] * values[f, 1]
                         + v[won] * values[f, 2])


def _write_indexed_gif(path: Path, indices: list[np.ndarray], duration: float) -> Path:
    from PIL import Image

    colours = palette().ravel().tolist()
    frames = []
    for index in indices:
        frame = Image.fromarray(index, mode="P")
        frame.putpalette(colours)
        frames.append(frame)
    buffer = io.BytesIO()
    # GIF durations are milliseconds (most viewers round them to 10 ms).
    frames[0].save(buffer, format="GIF", save_all=True, append_images=frames[1:],
                   duration=round(1000 * duration), loop=0)
    return atomic_write_bytes(path, buffer.getvalue())


def _write_rgb(path: Path, images: list[np.ndarray], duration: float) -> Path:
    import imageio.v3 as iio

    if path.suffix.lower() == ".mp4":
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError as error:
            raise ImportError("MP4 previews need the optional package imageio-ffmpeg "
                              "(pip install imageio-ffmpeg); write a .gif instead") from error
        data = iio.imwrite("<bytes>", np.stack(images), extension=".mp4",
                           fps=max(1.0, 1.0 / duration))
    else:
        data = iio.imwrite("<bytes>", np.stack(images), extension=".gif",
                           duration=round(1000 * duration), loop=0)
    return atomic_write_bytes(path, data)


def _camera(azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orthonormal (right, up, forward) of a camera looking at the body's front (+Y in
    the Z-up world, from −Y) turned by ``azimuth`` about Z and tilted down by
    ``elevation``."""
    a, e = np.radians(azimuth), np.radians(elevation)
    # Camera position direction (unit), from the target towards the eye.
    eye = np.array([np.sin(a) * np.cos(e), -np.cos(a) * np.cos(e), np.sin(e)])
    forward = -eye
    right = _normalised(np.cross(forward, [0.0, 0.0, 1.0]))
    up = np.cross(right, forward)
    return right, up, forward


def _normalised(vector: np.ndarray) -> np.ndarray:
    return vector / np.linalg.norm(vector)
