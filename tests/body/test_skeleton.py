import math

import pytest
import torch

from gnngarment.body.rotations import axis_angle_to_matrix, matrix_to_axis_angle, rotation_between
from gnngarment.body.skeleton import (
    JOINT_NAMES,
    JOINT_PARENTS,
    MIRROR_JOINTS,
    NUM_JOINTS,
    forward_kinematics,
)


def test_tree_is_smpl_order():
    assert len(JOINT_NAMES) == len(JOINT_PARENTS) == NUM_JOINTS == 24
    assert JOINT_PARENTS[0] == -1
    assert all(0 <= p < j for j, p in enumerate(JOINT_PARENTS) if j > 0)
    assert JOINT_NAMES[16] == "L_shoulder" and JOINT_PARENTS[16] == 13
    assert JOINT_NAMES[MIRROR_JOINTS[JOINT_NAMES.index("L_wrist")]] == "R_wrist"


def test_axis_angle_roundtrip_and_small_angles():
    torch.manual_seed(0)
    rotvec = torch.randn(100, 3, dtype=torch.float64)
    rotvec = rotvec / rotvec.norm(dim=1, keepdim=True) * torch.rand(100, 1, dtype=torch.float64) * 3
    matrix = axis_angle_to_matrix(rotvec)
    assert torch.allclose(
        matrix @ matrix.transpose(-1, -2),
        torch.eye(3, dtype=torch.float64).expand(100, 3, 3),
        atol=1e-12,
    )
    assert torch.allclose(matrix_to_axis_angle(matrix), rotvec, atol=1e-9)
    assert torch.allclose(axis_angle_to_matrix(torch.zeros(3)), torch.eye(3))
    z = torch.tensor([0.0, 0.0, math.pi / 2])
    assert torch.allclose(
        axis_angle_to_matrix(z) @ torch.tensor([1.0, 0, 0]), torch.tensor([0.0, 1, 0]), atol=1e-6
    )


def test_rotation_between():
    a = torch.tensor([1.0, 2.0, -0.5], dtype=torch.float64)
    b = torch.tensor([-1.0, 0.3, 0.2], dtype=torch.float64)
    r = rotation_between(a, b)
    assert torch.allclose(r @ (a / a.norm()), b / b.norm(), atol=1e-12)
    assert torch.allclose(rotation_between(a, -a) @ a, -a, atol=1e-12)


def test_fk_identity_and_translation():
    rest = torch.randn(NUM_JOINTS, 3)
    transforms, joints = forward_kinematics(
        torch.zeros(2, NUM_JOINTS, 3), rest, torch.tensor([[0, 0, 0], [1.0, 2, 3]])
    )
    assert torch.allclose(transforms[0], torch.eye(4).expand(NUM_JOINTS, 4, 4))
    assert torch.allclose(joints[1], rest + torch.tensor([1.0, 2, 3]), atol=1e-6)


def test_fk_rotates_about_joints():
    rest = torch.randn(NUM_JOINTS, 3, dtype=torch.float64)
    rotations = torch.zeros(NUM_JOINTS, 3, dtype=torch.float64)
    rotations[0] = torch.tensor([0.3, -0.2, 0.5])
    _, joints = forward_kinematics(rotations, rest)
    R = axis_angle_to_matrix(rotations[0])
    expected = (rest - rest[0]) @ R.T + rest[0]
    assert torch.allclose(joints, expected, atol=1e-12)
    # Elbow rotation moves the wrist about the elbow, not the shoulder.
    rotations = torch.zeros(NUM_JOINTS, 3, dtype=torch.float64)
    rotations[18] = torch.tensor([0.0, 0.0, 1.0])
    _, joints = forward_kinematics(rotations, rest)
    assert torch.allclose(joints[16], rest[16])
    assert torch.allclose((joints[20] - joints[18]).norm(), (rest[20] - rest[18]).norm())
    assert not torch.allclose(joints[20], rest[20])


def test_fk_transforms_map_rest_to_posed_joints():
    torch.manual_seed(1)
    rest = torch.randn(NUM_JOINTS, 3, dtype=torch.float64)
    transforms, joints = forward_kinematics(
        0.4 * torch.randn(5, NUM_JOINTS, 3, dtype=torch.float64),
        rest,
        torch.randn(5, 3, dtype=torch.float64),
    )
    mapped = (transforms[..., :3, :3] @ rest[None, :, :, None])[..., 0] + transforms[..., :3, 3]
    assert torch.allclose(mapped, joints)
    # A child's rest position is carried by its parent's transform.
    for j in range(1, NUM_JOINTS):
        p = JOINT_PARENTS[j]
        carried = (transforms[:, p, :3, :3] @ rest[j]) + transforms[:, p, :3, 3]
        assert torch.allclose(carried, joints[:, j])


def test_fk_validates_shapes():
    with pytest.raises(ValueError, match="rotations"):
        forward_kinematics(torch.zeros(23, 3), torch.zeros(24, 3))
    with pytest.raises(ValueError, match="rest_joints"):
        forward_kinematics(torch.zeros(24, 3), torch.zeros(23, 3))
