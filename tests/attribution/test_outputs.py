"""PLY and PNG outputs: vertex order, colours, atomic writes, validators."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.attribution import (
    heat_colors,
    normalise_heat,
    render_attribution,
    render_comparison,
    write_attribution_ply,
)
from tests.meshes import interleave, tube, union


@pytest.fixture(scope="module")
def mesh_and_heat() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A relabelled tube plus an exact copy on top of it: processing would merge the
    coincident vertices and reorder, so order-keeping is really tested."""
    pos, faces = interleave(*union(tube(6, 8), tube(6, 8), offset=0.0), seed=4)
    heat = np.random.default_rng(0).random(len(pos)) ** 3
    return pos, faces, heat


def test_ply_keeps_vertex_order_and_colours(tmp_path, mesh_and_heat) -> None:
    import trimesh

    pos, faces, heat = mesh_and_heat
    path = write_attribution_ply(tmp_path / "garment.ply", pos, faces, heat, scale="log")
    loaded = trimesh.load(path, process=False)
    assert len(loaded.vertices) == len(pos) == 96
    np.testing.assert_allclose(loaded.vertices, pos, atol=1e-6)     # float32 in the file
    np.testing.assert_array_equal(loaded.faces, faces)
    expected = heat_colors(normalise_heat(heat, "log"))
    np.testing.assert_array_equal(loaded.visual.vertex_colors, expected)
    assert len(np.unique(expected, axis=0)) > 10                      # really coloured
    header = path.read_bytes().split(b"end_header")[0]
    assert b"property float attribution" in header and b"property float quality" in header
    assert [p.name for p in tmp_path.iterdir()] == ["garment.ply"]    # no temp files left


def test_png_written(tmp_path, mesh_and_heat) -> None:
    from matplotlib.image import imread

    pos, faces, heat = mesh_and_heat
    single = render_attribution(tmp_path / "one.png", pos, faces, heat, targets=[5],
                                title="vertex 5")
    pair = render_comparison(tmp_path / "two.png", pos, faces, [heat, heat ** 2],
                             ["a", "b"], targets=[5, 6], scale="log", suptitle="compare")
    for path in (single, pair):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        image = imread(path)
        assert image.ndim == 3 and image.shape[0] > 200 and image.shape[1] > 400
        assert image[..., :3].std() > 0.05                            # not a blank canvas
    assert sorted(p.name for p in tmp_path.iterdir()) == ["one.png", "two.png"]


def test_normalise_heat() -> None:
    heat = np.array([0.0, 1e-4, 1e-2, 1.0]) * 3.0
    np.testing.assert_allclose(normalise_heat(heat), [0.0, 1e-4, 1e-2, 1.0])
    np.testing.assert_allclose(normalise_heat(heat, "log"), [0.0, 0.0, 0.5, 1.0])
    np.testing.assert_array_equal(normalise_heat(np.zeros(3)), np.zeros(3))
    colors = heat_colors(np.array([0.0, 1.0]))
    assert colors.dtype == np.uint8 and colors.shape == (2, 4)
    assert (colors[:, 3] == 255).all() and colors[1, :3].sum() > colors[0, :3].sum()


@pytest.mark.parametrize(("call", "message"), [
    (lambda p, f, h, d: write_attribution_ply(d / "x.ply", p, f, h[:-1]), "heat must have shape"),
    (lambda p, f, h, d: write_attribution_ply(d / "x.ply", p, f, -h), "non-negative"),
    (lambda p, f, h, d: write_attribution_ply(d / "x.ply", p[:, :2], f, h), r"pos must have"),
    (lambda p, f, h, d: render_attribution(d / "x.png", p, f, h, targets=[len(p)]),
     "targets must be vertex indices"),
    (lambda p, f, h, d: render_attribution(d / "x.png", p, f, h, scale="cubic"),
     "unknown colour scale 'cubic'"),
    (lambda p, f, h, d: render_comparison(d / "x.png", p, f, [h, h], ["one"]),
     "one title per heat"),
    (lambda p, f, h, d: render_comparison(d / "x.png", p, f, [h[:3]], ["one"]),
     "heat must have shape"),
])
def test_bad_outputs(tmp_path, mesh_and_heat, call, message) -> None:
    pos, faces, heat = mesh_and_heat
    with pytest.raises(ValueError, match=message):
        call(pos, faces, heat, tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_is_readable_and_keeps_the_mode(tmp_path) -> None:
    from gnngarment.io.atomic import atomic_write_bytes

    path = atomic_write_bytes(tmp_path / "sub" / "a.bin", b"one")
    assert path.read_bytes() == b"one" and path.stat().st_mode & 0o777 == 0o644
    path.chmod(0o600)
    atomic_write_bytes(path, b"two")
    assert path.read_bytes() == b"two" and path.stat().st_mode & 0o777 == 0o600
