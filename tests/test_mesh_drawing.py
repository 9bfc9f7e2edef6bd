"""The static-picture renderer: camera conventions and the painter's depth order."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.mesh_drawing import DrawnMesh, draw_meshes, project, view_rotation


@pytest.mark.parametrize("azimuth, elevation", [(0.0, 0.0), (37.0, 12.0), (-90.0, -20.0)])
def test_view_rotation_is_a_rotation(azimuth, elevation) -> None:
    rotation = view_rotation(azimuth, elevation)
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(rotation) == pytest.approx(1.0)


@pytest.mark.parametrize("azimuth, camera_side", [
    (0.0, [0.0, -1.0, 0.0]),     # the body's front faces −Y
    (180.0, [0.0, 1.0, 0.0]),
    (-90.0, [1.0, 0.0, 0.0]),
    (90.0, [-1.0, 0.0, 0.0]),
])
def test_azimuth_puts_the_camera_where_the_docstring_says(azimuth, camera_side) -> None:
    camera = project(np.array([camera_side, np.negative(camera_side), [0.0, 0.0, 1.0]]),
                     azimuth, 0.0)
    assert camera[0, 2] == pytest.approx(1.0)        # nearest the viewer
    assert camera[1, 2] == pytest.approx(-1.0)
    np.testing.assert_allclose(camera[2], [0.0, 1.0, 0.0], atol=1e-12)  # Z stays up


def test_elevation_looks_down_from_above() -> None:
    top, bottom = project(np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]), 0.0, 30.0)
    assert top[2] > bottom[2]


def _square(y: float) -> tuple[np.ndarray, np.ndarray]:
    pos = np.array([[-1.0, y, -1.0], [1.0, y, -1.0], [1.0, y, 1.0], [-1.0, y, 1.0]])
    return pos, np.array([[0, 1, 2], [0, 2, 3]])


def _pixel(meshes: list[DrawnMesh], azimuth: float) -> np.ndarray:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(1, 1), dpi=40)
    canvas = FigureCanvasAgg(figure)
    draw_meshes(figure.add_axes((0, 0, 1, 1)), meshes, azimuth, 0.0)
    canvas.draw()
    image = np.asarray(canvas.buffer_rgba())
    # Off the squares' diagonal, where the two triangles' antialiased seams meet.
    return image[image.shape[0] // 2, image.shape[1] // 4, :3] / 255.0


def test_the_nearer_mesh_hides_the_farther_from_either_side() -> None:
    red = DrawnMesh(*_square(-0.5), (1.0, 0.0, 0.0), lit=False)   # in front of the body
    blue = DrawnMesh(*_square(0.5), (0.0, 0.0, 1.0), lit=False)
    for meshes in ([red, blue], [blue, red]):  # the list order must not matter
        np.testing.assert_allclose(_pixel(meshes, 0.0), [1.0, 0.0, 0.0], atol=0.02)
        np.testing.assert_allclose(_pixel(meshes, 180.0), [0.0, 0.0, 1.0], atol=0.02)


def test_lit_faces_are_darker_from_behind_and_per_face_colours_pass_through() -> None:
    pos, faces = _square(0.0)  # wound so that its normal points at −Y, the front camera
    colors = np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    front = _pixel([DrawnMesh(pos, faces, colors)], 0.0)
    back = _pixel([DrawnMesh(pos, faces, colors)], 180.0)
    assert front[0] == front[2] == 0.0 and back[0] == back[2] == 0.0
    assert 0.0 < back[1] < front[1] <= 1.0
