"""Check an :class:`~gnngarment.inference.animate.Animation` before exporting it."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from gnngarment.body.skeleton import NUM_JOINTS
from gnngarment.io.obj import check_texture_coordinates

if TYPE_CHECKING:
    from gnngarment.inference.animate import Animation


def check_animation(animation: Animation, body: bool = False) -> None:
    """Raise a ``ValueError`` naming the first inconsistent array.

    Checks the shapes the exporters rely on: ``rest_pos (N, 3)``, ``faces (F, 3)`` with
    indices in range, ``posed (T, N, 3)`` with ``T ≥ 1``, ``weights (T, N, 24)``,
    ``joint_transforms (T, 24, 4, 4)``, ``rest_joints (24, 3)``, ``fps > 0``, all finite;
    ``uv (K, 2)`` and ``uv_faces (F, 3)`` both or neither; with ``body`` also
    ``body_vertices (T, N_b, 3)`` and ``body_faces (F_b, 3)``.
    """
    rest = np.asarray(animation.rest_pos)
    posed = np.asarray(animation.posed)
    if rest.ndim != 2 or rest.shape[1] != 3 or len(rest) == 0:
        raise ValueError(f"rest_pos must be (N, 3) with N ≥ 1, got {rest.shape}")
    count = len(rest)
    _check_faces(np.asarray(animation.faces), count, "faces")
    if posed.ndim != 3 or posed.shape[1:] != (count, 3) or len(posed) == 0:
        raise ValueError(f"posed must be (T, {count}, 3) with T ≥ 1, got {posed.shape}")
    frames = len(posed)
    expected = {
        "weights": (np.asarray(animation.weights), (frames, count, NUM_JOINTS)),
        "joint_transforms": (np.asarray(animation.joint_transforms),
                             (frames, NUM_JOINTS, 4, 4)),
        "rest_joints": (np.asarray(animation.rest_joints), (NUM_JOINTS, 3)),
    }
    for name, (array, shape) in expected.items():
        if array.shape != shape:
            raise ValueError(f"{name} must be {shape}, got {array.shape}")
    for name, array in [("rest_pos", rest), ("posed", posed)] + [
            (name, array) for name, (array, _) in expected.items()]:
        if not np.isfinite(array).all():
            raise ValueError(f"{name} contains NaN or inf")
    if not (np.isfinite(animation.fps) and animation.fps > 0):
        raise ValueError(f"fps must be positive, got {animation.fps}")
    if (animation.uv is None) != (animation.uv_faces is None):
        raise ValueError("uv and uv_faces must be given together (or both None)")
    if animation.uv is not None:
        check_texture_coordinates(animation.uv, animation.uv_faces, len(animation.faces))
    if body:
        vertices = np.asarray(animation.body_vertices)
        if vertices.ndim != 3 or vertices.shape[0] != frames or vertices.shape[2] != 3:
            raise ValueError(f"body_vertices must be ({frames}, N_b, 3), got {vertices.shape}")
        if not np.isfinite(vertices).all():
            raise ValueError("body_vertices contains NaN or inf")
        _check_faces(np.asarray(animation.body_faces), vertices.shape[1], "body_faces")


def _check_faces(faces: np.ndarray, count: int, name: str) -> None:
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        raise ValueError(f"{name} must be (F, 3) with F ≥ 1, got {faces.shape}")
    if not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"{name} must hold integers, got {faces.dtype}")
    if faces.min() < 0 or faces.max() >= count:
        raise ValueError(f"{name} indices span [{faces.min()}, {faces.max()}], "
                         f"outside [0, {count - 1}]")
