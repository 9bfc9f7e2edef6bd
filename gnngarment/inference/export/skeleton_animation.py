"""Per-joint local translation/rotation tracks from skinning transforms (for glTF, FBX-like
rigs): the canonical skeleton as a node hierarchy whose animation reproduces ``G``.

Conventions (see :mod:`gnngarment.body.skeleton`): the rest pose of every joint is a pure
translation to its rest position ``J_j`` (world-aligned axes), and the skinning
transform is ``G_j = global_posed_j · global_rest_j⁻¹``. Hence

    global_posed_j = G_j · T(J_j)
    local_j        = global_posed_parent⁻¹ · global_posed_j
    inverse bind_j = T(−J_j)

and a viewer that composes the locals down the hierarchy and multiplies by the inverse
bind matrix gets back ``G_j``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnngarment.body.skeleton import JOINT_PARENTS


@dataclass(frozen=True)
class SkeletonAnimation:
    """Node-hierarchy form of a skeleton motion.

    Attributes:
        rest_translations: ``(24, 3)`` local rest translation of each joint node (the
            root's is its world rest position, the others ``J_j − J_parent``).
        inverse_bind: ``(24, 4, 4)`` inverse bind matrices ``T(−J_j)``.
        translations: ``(T, 24, 3)`` animated local translations.
        rotations: ``(T, 24, 4)`` animated local rotations, unit quaternions ``(x, y, z, w)``
            with signs chosen continuous in time (so interpolation takes the short way).
        parents: parent index of each joint (−1 for the root).
    """

    rest_translations: np.ndarray
    inverse_bind: np.ndarray
    translations: np.ndarray
    rotations: np.ndarray
    parents: tuple[int, ...]

    def skinning_transforms(self) -> np.ndarray:
        """``(T, 24, 4, 4)`` float64 ``G_j`` recomposed from the tracks (a viewer's view)."""
        local = rigid_matrices(quaternion_to_matrix(self.rotations), self.translations)
        chain: list[np.ndarray] = []
        for j, parent in enumerate(self.parents):
            chain.append(local[:, j] if parent < 0 else chain[parent] @ local[:, j])
        return np.stack(chain, axis=1) @ self.inverse_bind


def skeleton_animation(joint_transforms: np.ndarray, rest_joints: np.ndarray,
                       parents: tuple[int, ...] = JOINT_PARENTS) -> SkeletonAnimation:
    """Local joint tracks whose composition reproduces the skinning transforms.

    The rotation part of each ``G_j`` is projected onto the nearest rotation first (float32
    transforms drift from orthogonality by ~1e-7; a body model with scale would drift
    more), so quaternions are exactly unit; the posed joint position ``G_j J_j`` is kept.

    Args:
        joint_transforms: ``(T, 24, 4, 4)`` skinning transforms, rest world → posed world.
        rest_joints: ``(24, 3)`` rest joint positions, metres.
        parents: the kinematic tree (parents before children).

    Returns:
        The tracks, float64.

    Raises:
        ValueError: wrong shapes, non-finite values or a parent after its child.
    """
    transforms = np.asarray(joint_transforms, dtype=np.float64)
    rest = np.asarray(rest_joints, dtype=np.float64)
    count = len(parents)
    if transforms.ndim != 4 or transforms.shape[1:] != (count, 4, 4):
        raise ValueError(f"joint_transforms must be (T, {count}, 4, 4), got {transforms.shape}")
    if rest.shape != (count, 3):
        raise ValueError(f"rest_joints must be ({count}, 3), got {rest.shape}")
    if not (np.isfinite(transforms).all() and np.isfinite(rest).all()):
        raise ValueError("joint_transforms or rest_joints contain NaN or inf")
    if any(parent >= j for j, parent in enumerate(parents)):
        raise ValueError("parents must list every parent before its children")
    rotation = nearest_rotation(transforms[..., :3, :3])  # (T, J, 3, 3) global posed
    position = (transforms[..., :3, :3] @ rest[:, :, None])[..., 0] + transforms[..., :3, 3]
    local_rotation = np.empty_like(rotation)
    local_translation = np.empty_like(position)
    rest_translation = np.empty_like(rest)
    for j, parent in enumerate(parents):
        if parent < 0:
            local_rotation[:, j] = rotation[:, j]
            local_translation[:, j] = position[:, j]
            rest_translation[j] = rest[j]
            continue
        inverse = np.swapaxes(rotation[:, parent], -1, -2)
        local_rotation[:, j] = inverse @ rotation[:, j]
        local_translation[:, j] = (inverse @ (position[:, j] - position[:, parent])[..., None])[
            ..., 0]
        rest_translation[j] = rest[j] - rest[parent]
    inverse_bind = np.tile(np.eye(4), (count, 1, 1))
    inverse_bind[:, :3, 3] = -rest
    return SkeletonAnimation(
        rest_translations=rest_translation, inverse_bind=inverse_bind,
        translations=local_translation,
        rotations=continuous_quaternions(matrix_to_quaternion(local_rotation)),
        parents=tuple(parents))


def nearest_rotation(matrices: np.ndarray) -> np.ndarray:
    """The rotation closest (Frobenius) to each ``(..., 3, 3)`` matrix: ``U Vᵀ`` of its SVD
    with the sign of the last axis fixed so the determinant is +1."""
    u, _, vt = np.linalg.svd(matrices)
    sign = np.where(np.linalg.det(u @ vt) < 0, -1.0, 1.0)
    u[..., :, 2] *= sign[..., None]
    return u @ vt


def matrix_to_quaternion(matrices: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(..., 4)`` as ``(x, y, z, w)`` (glTF order) of rotations
    ``(..., 3, 3)``, by Shepperd's method (stable for every angle)."""
    m = np.asarray(matrices, dtype=np.float64)
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    # Four candidate largest components; pick per element the best conditioned one.
    candidates = np.stack([
        np.stack([1 + m00 - m11 - m22, m[..., 0, 1] + m[..., 1, 0],
                  m[..., 0, 2] + m[..., 2, 0], m[..., 2, 1] - m[..., 1, 2]], -1),
        np.stack([m[..., 0, 1] + m[..., 1, 0], 1 - m00 + m11 - m22,
                  m[..., 1, 2] + m[..., 2, 1], m[..., 0, 2] - m[..., 2, 0]], -1),
        np.stack([m[..., 0, 2] + m[..., 2, 0], m[..., 1, 2] + m[..., 2, 1],
                  1 - m00 - m11 + m22, m[..., 1, 0] - m[..., 0, 1]], -1),
        np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                  m[..., 1, 0] - m[..., 0, 1], 1 + m00 + m11 + m22], -1),
    ], axis=-2)  # (..., 4 candidates, 4)
    diagonal = np.stack([1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22,
                         1 + m00 + m11 + m22], -1)
    best = np.argmax(diagonal, axis=-1)
    q = np.take_along_axis(candidates, best[..., None, None], axis=-2)[..., 0, :]
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., 3:] < 0, -q, q)  # w ≥ 0, one canonical sign


def quaternion_to_matrix(quaternions: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of quaternions ``(..., 4)`` in ``(x, y, z, w)``
    order (normalised first)."""
    q = np.asarray(quaternions, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=-2)


def continuous_quaternions(quaternions: np.ndarray) -> np.ndarray:
    """Flip signs along axis 0 (time) so consecutive quaternions have a non-negative dot
    product: ``q`` and ``−q`` are the same rotation, but interpolating between opposite
    signs would spin the long way round."""
    q = np.array(quaternions, dtype=np.float64, copy=True)
    for t in range(1, len(q)):
        flip = np.sum(q[t] * q[t - 1], axis=-1) < 0
        q[t][flip] *= -1.0
    return q


def rigid_matrices(rotations: np.ndarray, translations: np.ndarray) -> np.ndarray:
    """``(..., 4, 4)`` from rotations ``(..., 3, 3)`` and translations ``(..., 3)``."""
    out = np.zeros((*rotations.shape[:-2], 4, 4))
    out[..., :3, :3] = rotations
    out[..., :3, 3] = translations
    out[..., 3, 3] = 1.0
    return out

