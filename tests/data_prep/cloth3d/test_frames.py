"""CLOTH3D's world frame, the root turn and the rest alignment."""

from __future__ import annotations

import numpy as np
import pytest

from data_prep.cloth3d import (
    from_world,
    rest_alignment,
    to_world,
    unroot_frames,
    world_transform,
    z_rotation,
)


def test_to_world_and_from_world_are_inverse() -> None:
    rng = np.random.default_rng(3)
    points, trans = rng.normal(size=(4, 9, 3)), rng.normal(size=(4, 3))
    np.testing.assert_allclose(from_world(to_world(points, trans, 0.8), trans, 0.8), points,
                               atol=1e-12)
    np.testing.assert_allclose(to_world(from_world(points, trans, -2.0), trans, -2.0), points,
                               atol=1e-12)
    assert to_world(points.astype(np.float32), trans, 0.8).dtype == np.float32


def test_moving_root_lands_where_expected() -> None:
    # A point 1 m above the root while the root walks +x at 1 m per frame; the sequence
    # is turned 90° about +z, so the walk goes along +y in the world.
    num_frames = 4
    trans = np.column_stack([np.arange(num_frames), np.zeros(num_frames), np.full(num_frames, 0.9)])
    points = np.tile([[0.0, 0.0, 1.0], [0.5, 0.0, 0.0]], (num_frames, 1, 1))  # (T, 2, 3)

    world = to_world(points, trans, np.pi / 2)

    t = np.arange(num_frames)
    np.testing.assert_allclose(world[:, 0], np.column_stack([0 * t, t, 1.9 + 0 * t]), atol=1e-12)
    np.testing.assert_allclose(world[:, 1], np.column_stack([0 * t, t + 0.5, 0.9 + 0 * t]),
                               atol=1e-12)
    # Joints as (T, 3) (one point per frame) use the same function.
    np.testing.assert_allclose(to_world(np.zeros((num_frames, 3)), trans, np.pi / 2)[:, :2],
                               np.column_stack([0 * t, t]), atol=1e-12)


def test_world_transform_matches_to_world_for_points_and_rigid_transforms() -> None:
    rng = np.random.default_rng(4)
    trans, zrot = rng.normal(size=(3, 3)), 1.1
    points = rng.normal(size=(3, 5, 3))
    transforms = world_transform(trans, zrot)
    homogeneous = np.concatenate([points, np.ones((3, 5, 1))], axis=2)
    np.testing.assert_allclose(np.einsum("tij,tnj->tni", transforms, homogeneous)[..., :3],
                               to_world(points, trans, zrot), atol=1e-12)
    # A joint's rigid transform G (cache frame) composed with W: its origin goes to_world.
    joint = np.eye(4)
    joint[:3, 3] = [0.1, 0.2, 0.3]
    np.testing.assert_allclose((transforms @ joint)[:, :3, 3],
                               to_world(np.tile(joint[:3, 3], (3, 1)), trans, zrot), atol=1e-12)


def test_z_rotation_direction() -> None:
    np.testing.assert_allclose(z_rotation(np.pi / 2) @ [1.0, 0, 0], [0, 1, 0], atol=1e-15)


def posed_about_the_root(rest: np.ndarray, root_rotations: np.ndarray) -> np.ndarray:
    """``(T, N, 3)``: ``rest`` carried by each frame's root rotation relative to the rest
    root (+90° about x), as a garment glued to the pelvis would be in the cache frame."""
    from scipy.spatial.transform import Rotation

    rest_root = Rotation.from_rotvec([np.pi / 2, 0, 0])
    return np.stack([(Rotation.from_rotvec(r) * rest_root.inv()).apply(rest)
                     for r in root_rotations])


def test_unroot_frames_undoes_the_root_rotation_relative_to_the_rest_root() -> None:
    rng = np.random.default_rng(3)
    rest = rng.normal(0, 0.2, (7, 3))
    roots = rng.normal(0, 1.0, (4, 3))
    frames = posed_about_the_root(rest, roots)
    np.testing.assert_allclose(unroot_frames(frames, roots), np.tile(rest, (4, 1, 1)),
                               atol=1e-12)
    # The rest pose's own root rotation (+90° about x) leaves a frame where it is.
    still = unroot_frames(rest[None], np.array([[np.pi / 2, 0, 0]]))[0]
    np.testing.assert_allclose(still, rest, atol=1e-12)


def test_rest_alignment_measures_turn_and_distance() -> None:
    """A template glued to the root: turn 0 and distance 0. The same template stored
    turned by −0.5 rad reads as turned +0.5 rad (what maps it back onto the frames);
    one stored 0.3 m too high reads as 0.3 m away with no turn."""
    rng = np.random.default_rng(4)
    rest = rng.normal(0, 0.2, (50, 3))
    roots = rng.normal(0, 1.0, (6, 3))
    frames = posed_about_the_root(rest, roots)

    good = rest_alignment(rest, frames, roots)
    assert good.turn.shape == good.distance.shape == (6,)
    np.testing.assert_allclose(good.turn, 0, atol=1e-9)
    assert abs(good.fitted_turn) < 1e-9 and good.median_distance < 1e-9
    assert good.problem() is None

    turned = rest_alignment(rest @ z_rotation(-0.5).T, frames, roots)
    np.testing.assert_allclose(turned.turn, 0.5, atol=1e-9)
    assert turned.fitted_turn == pytest.approx(0.5)
    assert "turned +29°" in turned.problem()
    assert turned.problem(max_turn=0.6, max_distance=1.0) is None

    high = rest_alignment(rest + np.array([0, 0, 0.3]), frames, roots)
    assert high.median_distance == pytest.approx(0.3)
    assert abs(high.fitted_turn) < 0.05
    assert "0.30 m (median) from its frames" in high.problem()


def test_frame_functions_validate_shapes() -> None:
    with pytest.raises(ValueError, match=r"trans has shape \(2, 3\), expected \(T, 3\) = \(4, 3\)"):
        to_world(np.zeros((4, 5, 3)), np.zeros((2, 3)), 0.0)
    with pytest.raises(ValueError, match=r"expected \(T, \.\.\., 3\)"):
        from_world(np.zeros((4, 2)), np.zeros((4, 3)), 0.0)
    with pytest.raises(ValueError, match=r"expected \(T, 3\) = \(4, 3\)"):
        unroot_frames(np.zeros((4, 5, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"frames have shape \(5, 3\), expected \(T, N, 3\)"):
        unroot_frames(np.zeros((5, 3)), np.zeros((5, 3)))
    with pytest.raises(ValueError, match=r"rest_pos has shape \(4, 3, 3\), expected \(N, 3\)"):
        rest_alignment(np.zeros((4, 3, 3)), np.zeros((1, 4, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="frames have 5 vertices but rest_pos has 4"):
        rest_alignment(np.zeros((4, 3)), np.zeros((1, 5, 3)), np.zeros((1, 3)))
