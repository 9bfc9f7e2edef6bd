"""GIF previews: headless, every k-th frame, small and fast."""

from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

from gnngarment.inference.export.preview import (
    cluster_decimation,
    preview_frames,
    rasterize,
    render_preview,
)
from tests.inference.animations import synthetic_animation


def test_frame_stride_keeps_real_time_speed() -> None:
    frames, duration = preview_frames(100, fps=30.0, max_frames=48)
    assert frames.tolist() == list(range(0, 100, 3))
    assert duration == pytest.approx(0.1)
    assert preview_frames(5, 30.0)[0].tolist() == [0, 1, 2, 3, 4]


def test_gif_shows_the_garment_in_colour_on_a_grey_body(tmp_path: Path) -> None:
    animation = synthetic_animation(frames=6)
    calls = []
    path = render_preview(animation, tmp_path / "p.gif", size=128,
                          progress=lambda done, total: calls.append(done))
    images = iio.imread(path, index=None)
    assert images.shape == (6, 128, 128, 3)
    assert calls == [1, 2, 3, 4, 5, 6]
    pixels = images[0].reshape(-1, 3).astype(int)
    reddish = (pixels[:, 0] - pixels[:, 2] > 60).mean()
    greyish = ((np.ptp(pixels, axis=1) < 12) & (pixels.max(axis=1) < 235)).mean()
    assert reddish > 0.01 and greyish > 0.01
    assert not (images[0] == images[3]).all()  # it moves
    alone = iio.imread(render_preview(animation, tmp_path / "g.gif", size=128,
                                      include_body=False), index=None)
    assert ((np.ptp(alone[0].reshape(-1, 3).astype(int), axis=1) < 12)
            & (alone[0].reshape(-1, 3).max(axis=1) < 235)).mean() < greyish


def test_an_outfit_shows_each_garment_in_its_own_colour(tmp_path: Path) -> None:
    """Two garments drawn as one animation: the first red, the second blue."""
    animation = synthetic_animation(frames=2)
    half = len(animation.faces) // 2
    path = render_preview(animation, tmp_path / "o.gif", size=128, include_body=False,
                          garment_faces=[half, len(animation.faces) - half])
    pixels = iio.imread(path, index=None)[0].reshape(-1, 3).astype(int)
    reddish = (pixels[:, 0] - pixels[:, 2] > 60).mean()
    bluish = (pixels[:, 2] - pixels[:, 0] > 60).mean()
    assert reddish > 0.01 and bluish > 0.01
    one = iio.imread(render_preview(animation, tmp_path / "one.gif", size=128,
                                    include_body=False), index=None)[0].reshape(-1, 3)
    assert ((one[:, 2].astype(int) - one[:, 0]) > 60).mean() == 0  # alone: no blue
    with pytest.raises(ValueError, match="add up"):
        render_preview(animation, tmp_path / "x.gif", garment_faces=[1])


def test_rasterizer_matches_brute_force_nearest_triangle() -> None:
    rng = np.random.default_rng(0)
    size, count = 40, 30
    triangles = rng.uniform(-5, size + 5, (count, 3, 2))
    depths = rng.uniform(0, 1, (count, 3))
    values = np.repeat(np.arange(count, dtype=float)[:, None], 3, axis=1)
    image = rasterize(triangles, depths, values, size, background=-1.0, chunk=500)
    expected = np.full((size, size), -1.0)
    nearest = np.full((size, size), np.inf)
    y, x = np.mgrid[0:size, 0:size] + 0.5
    for f, (a, b, c) in enumerate(triangles):
        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        u = ((x - a[0]) * (c[1] - a[1]) - (y - a[1]) * (c[0] - a[0])) / area
        v = ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) / area
        depth = (1 - u - v) * depths[f, 0] + u * depths[f, 1] + v * depths[f, 2]
        wins = (u >= 0) & (v >= 0) & (u + v <= 1) & (depth < nearest)
        expected[wins], nearest[wins] = f, depth[wins]
    assert (image != expected).mean() < 0.005  # only ties on shared edges may differ
    assert (expected >= 0).mean() > 0.5


def test_cluster_decimation_is_shared_by_all_frames() -> None:
    animation = synthetic_animation(frames=3, body_rings=40, body_sections=48)
    labels, faces = cluster_decimation(animation.body_vertices, animation.body_faces, 800)
    assert len(faces) <= 800 and labels.shape == (animation.body_vertices.shape[1],)
    assert faces.max() == labels.max()
    assert (faces[:, 0] != faces[:, 1]).all() and (faces[:, 1] != faces[:, 2]).all()
    small = cluster_decimation(animation.body_vertices, animation.body_faces, 10**6)
    np.testing.assert_array_equal(small[1], animation.body_faces)


def test_bad_extension(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="must be .gif or .mp4"):
        render_preview(synthetic_animation(frames=2), tmp_path / "p.png")


@pytest.mark.slow
def test_sixty_frames_of_a_2k_garment_on_a_13k_body_make_a_small_gif(tmp_path) -> None:
    """(Its CPU time is measured by benchmarks/generation_and_preview_speed.py.)"""
    animation = synthetic_animation(frames=60, rings=40, sections=50, body_rings=130,
                                    body_sections=104)
    assert animation.body_vertices.shape[1] > 13000
    path = render_preview(animation, tmp_path / "p.gif", max_frames=60)
    assert len(iio.imread(path, index=None)) == 60
    assert path.stat().st_size < 3e6
