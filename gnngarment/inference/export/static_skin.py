"""A static K-influence skin for per-frame dense skinning weights, and the rest-frame
residuals that make "static skin + per-frame offsets" reproduce the prediction.

The model predicts dense weights ``W^t (N, 24)`` that change every frame, and engines
skin with one fixed set of at most 4 (or 8) influences per vertex. With the static
weights ``w̄`` the blended transform of vertex ``i`` at frame ``t`` is
``A_i^t = Σ_j w̄_ij G_j^t = [M_i^t | b_i^t]``; the offset

    d_i^t = (M_i^t)⁻¹ (x_i^t − b_i^t) − r_i

added to the rest position ``r_i`` before skinning (a glTF morph target: morphing
happens before skinning) gives back the predicted ``x_i^t`` exactly, up to float32.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: |det M| below which a blended transform counts as ill-conditioned (a convex blend
#: of rotations has det ≈ 1; near-opposite rotations blended half/half approach 0).
SINGULAR_DET = 1e-3


@dataclass(frozen=True)
class StaticSkin:
    """At most ``K`` influences per vertex.

    Attributes:
        joints: ``(N, K)`` int64 joint indices, distinct per vertex among non-zero
            weights; a zero weight's index is 0 (what the glTF validator expects).
        weights: ``(N, K)`` float32, non-negative, descending, rows summing to 1 to
            within float32 rounding (the largest weight absorbs the others' rounding).
    """

    joints: np.ndarray
    weights: np.ndarray

    def dense(self, num_joints: int = 24) -> np.ndarray:
        """``(N, num_joints)`` float64 dense weights."""
        out = np.zeros((len(self.joints), num_joints))
        np.add.at(out, (np.arange(len(self.joints))[:, None], self.joints),
                  self.weights.astype(np.float64))
        return out


def static_skin(weights: np.ndarray, max_influences: int = 4,
                reference: str | int = "mean") -> StaticSkin:
    """The top-``K`` weights of one reference weight set, renormalised.

    Args:
        weights: ``(T, N, J)`` per-frame weights (or ``(N, J)``), non-negative.
        max_influences: ``K``, 4 (glTF ``JOINTS_0``) or 8 (``JOINTS_0`` + ``JOINTS_1``),
            any value in 1..J.
        reference: ``"mean"`` for the time-averaged weights, or a frame index.

    Raises:
        ValueError: bad shapes, negative or non-finite weights, a vertex whose reference
            weights are all zero, or a bad ``max_influences``/``reference``.
    """
    weights = np.asarray(weights, dtype=np.float64)
    if weights.ndim == 2:
        weights = weights[None]
    if weights.ndim != 3 or weights.shape[0] == 0:
        raise ValueError(f"weights must be (T, N, J) with T ≥ 1, got {weights.shape}")
    num_joints = weights.shape[2]
    if not 1 <= max_influences <= num_joints:
        raise ValueError(f"max_influences must be in 1..{num_joints}, got {max_influences}")
    if not np.isfinite(weights).all() or (weights < 0).any():
        raise ValueError("weights must be finite and non-negative")
    if reference == "mean":
        chosen = weights.mean(axis=0)
    elif isinstance(reference, (int, np.integer)) and -len(weights) <= reference < len(weights):
        chosen = weights[reference]
    else:
        raise ValueError(f"reference must be 'mean' or a frame index in "
                         f"[{-len(weights)}, {len(weights)}), got {reference!r}")
    k = max_influences
    top = np.argpartition(-chosen, k - 1, axis=1)[:, :k]
    top_weights = np.take_along_axis(chosen, top, axis=1)
    order = np.argsort(-top_weights, axis=1, kind="stable")
    top = np.take_along_axis(top, order, axis=1)
    top_weights = np.take_along_axis(top_weights, order, axis=1)
    total = top_weights.sum(axis=1, keepdims=True)
    if (total <= 0).any():
        bad = np.flatnonzero(total[:, 0] <= 0)[:8].tolist()
        raise ValueError(f"vertices {bad} have all-zero reference weights")
    normalised = (top_weights / total).astype(np.float32)
    # The first (largest) weight absorbs float32 rounding so rows sum to 1 exactly.
    normalised[:, 0] = (1.0 - normalised[:, 1:].astype(np.float64).sum(axis=1)).astype(
        np.float32)
    top = np.where(normalised > 0, top, 0)
    return StaticSkin(joints=top.astype(np.int64), weights=normalised)


def blended_transforms(skin: StaticSkin, joint_transforms: np.ndarray) -> np.ndarray:
    """``(N, 3, 4)`` float64 ``Σ_k w_ik G_{j_ik}`` for one frame's ``(J, 4, 4)``."""
    affine = np.asarray(joint_transforms, dtype=np.float64)[:, :3, :]
    return np.einsum("nk,nkab->nab", skin.weights.astype(np.float64), affine[skin.joints])


def skin_static(rest_pos: np.ndarray, offsets: np.ndarray | None, skin: StaticSkin,
                joint_transforms: np.ndarray) -> np.ndarray:
    """Static-skin LBS ``x_i^t = A_i^t [r_i + d_i^t; 1]``.

    Shapes:
        rest_pos ``(N, 3)``, offsets ``(T, N, 3)`` or ``None``, joint_transforms
        ``(T, J, 4, 4)`` → ``(T, N, 3)`` float64.
    """
    rest = np.asarray(rest_pos, dtype=np.float64)
    out = np.empty((len(joint_transforms), len(rest), 3))
    for t, transforms in enumerate(joint_transforms):
        blend = blended_transforms(skin, transforms)
        points = rest if offsets is None else rest + offsets[t]
        out[t] = np.einsum("nab,nb->na", blend[..., :3], points) + blend[..., 3]
    return out


@dataclass(frozen=True)
class Residuals:
    """Rest-frame offsets of a static skin.

    Attributes:
        offsets: ``(T, N, 3)`` float64 ``d^t`` (metres, rest frame).
        ill_conditioned: number of (frame, vertex) pairs whose blended transform had
            ``|det M| < SINGULAR_DET``; solved in the least-squares sense there, so those
            vertices may not be reproduced exactly (0 in practice).
    """

    offsets: np.ndarray
    ill_conditioned: int


def rest_frame_residuals(rest_pos: np.ndarray, posed: np.ndarray, skin: StaticSkin,
                         joint_transforms: np.ndarray) -> Residuals:
    """Per-frame offsets ``d^t`` with ``skin_static(rest_pos, d, …) == posed``.

    Args:
        rest_pos: ``(N, 3)`` rest (bind) positions.
        posed: ``(T, N, 3)`` target positions, world.
        skin: the static skin.
        joint_transforms: ``(T, J, 4, 4)`` the transforms the consumer will skin with
            (pass the ones a viewer recomposes from the exported tracks, so their float
            rounding is absorbed too).
    """
    rest = np.asarray(rest_pos, dtype=np.float64)
    posed = np.asarray(posed, dtype=np.float64)
    if posed.ndim != 3 or posed.shape[1:] != rest.shape or len(posed) != len(joint_transforms):
        raise ValueError(f"posed {posed.shape} does not match rest_pos {rest.shape} and "
                         f"{len(joint_transforms)} frames of joint_transforms")
    offsets = np.empty_like(posed)
    ill = 0
    for t, transforms in enumerate(joint_transforms):
        blend = blended_transforms(skin, transforms)
        matrix, shift = blend[..., :3], blend[..., 3]
        target = posed[t] - shift
        singular = np.abs(np.linalg.det(matrix)) < SINGULAR_DET
        solved = np.empty_like(target)
        good = ~singular
        solved[good] = np.linalg.solve(matrix[good], target[good][..., None])[..., 0]
        if singular.any():
            ill += int(singular.sum())
            solved[singular] = np.einsum("nab,nb->na", np.linalg.pinv(matrix[singular],
                                                                      rcond=1e-6),
                                         target[singular])
        offsets[t] = solved - rest
    return Residuals(offsets=offsets, ill_conditioned=ill)
