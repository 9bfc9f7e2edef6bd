"""Rotation conversions used across the body package (torch, differentiable).

Shapes:
    axis-angle ``(..., 3)`` (radians, direction = axis), rotation matrices ``(..., 3, 3)``.
"""

from __future__ import annotations

import torch


def axis_angle_to_matrix(axis_angle: torch.Tensor) -> torch.Tensor:
    """Rodrigues' formula, differentiable everywhere (including the zero rotation).

    Shapes:
        axis_angle ``(..., 3)`` → ``(..., 3, 3)``.
    """
    if axis_angle.shape[-1] != 3:
        raise ValueError(f"expected axis-angle of shape (..., 3), got {tuple(axis_angle.shape)}")
    angle_sq = (axis_angle * axis_angle).sum(-1, keepdim=True)
    small = angle_sq < 1e-12
    safe_sq = torch.where(small, torch.ones_like(angle_sq), angle_sq)
    angle = torch.sqrt(safe_sq)
    # sin(θ)/θ and (1 − cos θ)/θ², with their Taylor expansions near zero.
    a = torch.where(small, 1.0 - angle_sq / 6.0, torch.sin(angle) / angle)
    b = torch.where(small, 0.5 - angle_sq / 24.0, (1.0 - torch.cos(angle)) / safe_sq)
    x, y, z = axis_angle.unbind(-1)
    zero = torch.zeros_like(x)
    K = torch.stack([zero, -z, y, z, zero, -x, -y, x, zero], dim=-1).reshape(
        *axis_angle.shape[:-1], 3, 3
    )
    eye = torch.eye(3, dtype=axis_angle.dtype, device=axis_angle.device)
    return eye + a[..., None] * K + b[..., None] * (K @ K)


def matrix_to_axis_angle(matrix: torch.Tensor) -> torch.Tensor:
    """Inverse of :func:`axis_angle_to_matrix` (angle in [0, π]), via quaternions.

    Shapes:
        matrix ``(..., 3, 3)`` → ``(..., 3)``.
    """
    from scipy.spatial.transform import Rotation

    flat = matrix.detach().reshape(-1, 3, 3).cpu().double().numpy()
    rotvec = Rotation.from_matrix(flat).as_rotvec()
    return torch.as_tensor(rotvec, dtype=matrix.dtype, device=matrix.device).reshape(
        *matrix.shape[:-2], 3
    )


def rotation_between(source: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Shortest-arc rotation matrix taking direction ``source`` onto direction ``target``.

    Shapes:
        source ``(3,)``, target ``(3,)`` → ``(3, 3)``.
    """
    a = source / source.norm()
    b = target / target.norm()
    axis = torch.linalg.cross(a, b)
    sin = axis.norm()
    cos = torch.dot(a, b)
    if sin < 1e-12:
        if cos > 0:
            return torch.eye(3, dtype=a.dtype)
        # Opposite directions: half turn about any axis orthogonal to a.
        helper = torch.tensor([1.0, 0.0, 0.0], dtype=a.dtype)
        if abs(float(a[0])) > 0.9:
            helper = torch.tensor([0.0, 1.0, 0.0], dtype=a.dtype)
        axis = torch.linalg.cross(a, helper)
        return axis_angle_to_matrix(axis / axis.norm() * torch.pi)
    return axis_angle_to_matrix(axis / sin * torch.atan2(sin, cos))
