"""The spurious-correlation test of JointNet: perturb a joint that should not move the
garment and measure how much the prediction moves anyway."""

from __future__ import annotations

import numpy as np

from gnngarment.body.skeleton import JOINT_INDEX, JOINT_PARENTS

#: A joint each garment type should not depend on (documented in docs/evaluation.md).
IRRELEVANT_JOINT = {"skirt": "L_wrist", "trousers": "L_wrist", "dress": "L_wrist",
                    "tshirt": "L_ankle", "top": "L_ankle", "jumpsuit": "head"}
DEFAULT_IRRELEVANT_JOINT = "L_wrist"


def descendants(joint: int) -> list[int]:
    """``joint`` and every joint below it in the kinematic tree."""
    result = [joint]
    for child, parent in enumerate(JOINT_PARENTS):
        if parent >= 0 and parent in result and child not in result:
            result.append(child)
    return result


def _axis_angle_matrix(vector: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(vector).as_matrix()


def perturb_joint(motion_features: np.ndarray, joint_transforms: np.ndarray,
                  rest_joints: np.ndarray, joint: str, rotation: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Add a local rotation at ``joint`` to every frame.

    The motion features' axis-angle of the joint gets the extra rotation composed in,
    and the joint's subtree of skinning transforms is rotated about the rest joint:
    ``G'_d = G_j P G_j⁻¹ G_d`` with ``P = T(r_j) R T(−r_j)``. Body velocities are left
    unchanged (a hand moving barely changes the subset's velocities near a skirt).

    Shapes:
        motion_features ``(T, 75)``, joint_transforms ``(T, 24, 4, 4)``,
        rest_joints ``(24, 3)``, rotation ``(3,)`` axis-angle (radians).
    """
    from scipy.spatial.transform import Rotation

    j = JOINT_INDEX[joint]
    rotation_matrix = _axis_angle_matrix(np.asarray(rotation, dtype=np.float64))
    features = motion_features.astype(np.float64).copy()
    local = Rotation.from_rotvec(features[:, 3 * j:3 * j + 3])
    features[:, 3 * j:3 * j + 3] = (local * Rotation.from_matrix(rotation_matrix)).as_rotvec()

    pivot = np.eye(4)
    pivot[:3, :3] = rotation_matrix
    pivot[:3, 3] = rest_joints[j] - rotation_matrix @ rest_joints[j]
    transforms = joint_transforms.astype(np.float64).copy()
    change = transforms[:, j] @ pivot @ np.linalg.inv(transforms[:, j])   # (T, 4, 4)
    for d in descendants(j):
        transforms[:, d] = change @ joint_transforms[:, d]
    return features.astype(np.float32), transforms.astype(np.float32)
