"""The canonical 24-joint skeleton (SMPL order) and its forward kinematics.

Conventions, shared by every body model of the library:

* World frame: **Z up, metres**, the body faces **−Y**, its left is **+X** (Anny's frame,
  and Newton's default). SMPL data (Y up, facing +Z) is converted on load.
* The rest pose is the **T-pose** (arms horizontal along ±X, legs straight down): a
  motion whose rotations are all zero and translation zero reproduces the rest mesh.
* Local rotations are axis-angle vectors expressed in the **world-aligned axes of the
  rest pose** (every joint's rest frame is the world frame, as in SMPL), so the global
  rotation of joint ``j`` is ``R_root · … · R_parent(j) · R_j``. Joint 0's rotation is
  the body's world orientation; the root translation is added to the pelvis.
* The joint transform ``G_j`` (a 4×4 rigid transform) maps **rest-pose world
  coordinates to posed world coordinates** for points that move with joint ``j``: it is
  the skinning transform (SMPL's ``A``), i.e. the joint's posed global pose times the
  inverse of its rest global pose. Garment LBS is ``x = Σ_j w_j G_j [x_rest; 1]``.
"""

from __future__ import annotations

import torch

from gnngarment.body.rotations import axis_angle_to_matrix

NUM_JOINTS = 24

JOINT_NAMES: tuple[str, ...] = (
    "pelvis",
    "L_hip",
    "R_hip",
    "spine1",
    "L_knee",
    "R_knee",
    "spine2",
    "L_ankle",
    "R_ankle",
    "spine3",
    "L_foot",
    "R_foot",
    "neck",
    "L_collar",
    "R_collar",
    "head",
    "L_shoulder",
    "R_shoulder",
    "L_elbow",
    "R_elbow",
    "L_wrist",
    "R_wrist",
    "L_hand",
    "R_hand",
)

# Parent of each joint (−1 for the root), SMPL's kinematic tree.
JOINT_PARENTS: tuple[int, ...] = (
    -1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21,
)  # fmt: skip

JOINT_INDEX: dict[str, int] = {name: i for i, name in enumerate(JOINT_NAMES)}

# Left/right pairs (index of the mirrored joint), used to mirror motions.
MIRROR_JOINTS: tuple[int, ...] = tuple(
    JOINT_INDEX[
        name.replace("L_", "@").replace("R_", "L_").replace("@", "R_")
        if name[:2] in ("L_", "R_")
        else name
    ]
    for name in JOINT_NAMES
)


def rigid_transform(rotation: torch.Tensor, translation: torch.Tensor) -> torch.Tensor:
    """Stack ``(..., 3, 3)`` rotations and ``(..., 3)`` translations into ``(..., 4, 4)``."""
    top = torch.cat([rotation, translation[..., None]], dim=-1)
    bottom = torch.zeros(*top.shape[:-2], 1, 4, dtype=top.dtype, device=top.device)
    bottom[..., 0, 3] = 1.0
    return torch.cat([top, bottom], dim=-2)


def forward_kinematics(
    rotations: torch.Tensor,
    rest_joints: torch.Tensor,
    translation: torch.Tensor | None = None,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Joint transforms of the canonical skeleton (differentiable, batched).

    ``G_0 = [R_0 | J_0 − R_0 J_0 + t]`` and ``G_j = G_parent · [R_j | J_j − R_j J_j]``,
    the rotation of each joint acting about its rest position ``J_j``.

    Args:
        rotations: local rotations, axis-angle ``(..., 24, 3)`` or matrices
            ``(..., 24, 3, 3)``, in the world-aligned rest axes (module docstring).
        rest_joints: rest joint positions ``(24, 3)`` or ``(..., 24, 3)``, metres.
        translation: root translation ``(..., 3)`` added to the pelvis, or ``None``.

    Returns:
        ``(transforms, joints)``: the skinning transforms ``G`` ``(..., 24, 4, 4)`` mapping
        rest world coordinates to posed world coordinates, and the posed joint positions
        ``(..., 24, 3)``.
    """
    if rotations.shape[-1] == 3 and rotations.shape[-2] == NUM_JOINTS:
        matrices = axis_angle_to_matrix(rotations)
    elif rotations.shape[-2:] == (3, 3) and rotations.shape[-3] == NUM_JOINTS:
        matrices = rotations
    else:
        raise ValueError(
            f"rotations must be (..., {NUM_JOINTS}, 3) or (..., {NUM_JOINTS}, 3, 3), "
            f"got {tuple(rotations.shape)}"
        )
    if rest_joints.shape[-2:] != (NUM_JOINTS, 3):
        raise ValueError(
            f"rest_joints must be (..., {NUM_JOINTS}, 3), got {tuple(rest_joints.shape)}"
        )
    batch = matrices.shape[:-3]
    rest = rest_joints.to(matrices.dtype).expand(*batch, NUM_JOINTS, 3)
    # Local transform of each joint: rotation about its rest position.
    local_t = rest - (matrices @ rest[..., None])[..., 0]
    if translation is not None:
        if translation.shape[-1] != 3:
            raise ValueError(f"translation must be (..., 3), got {tuple(translation.shape)}")
        local_t = local_t.clone()
        local_t[..., 0, :] = local_t[..., 0, :] + translation.to(matrices.dtype)
    local = rigid_transform(matrices, local_t)
    chain = [local[..., 0, :, :]]
    for j in range(1, NUM_JOINTS):
        chain.append(chain[JOINT_PARENTS[j]] @ local[..., j, :, :])
    transforms = torch.stack(chain, dim=-3)
    joints = (transforms[..., :3, :3] @ rest[..., None])[..., 0] + transforms[..., :3, 3]
    return transforms, joints
