"""Skeleton previews: small multiples of a motion's frames (matplotlib, Agg backend)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from gnngarment.body.motion import Motion
from gnngarment.body.skeleton import JOINT_NAMES, JOINT_PARENTS, forward_kinematics


def skeleton_positions(motion: Motion, rest_joints: torch.Tensor | np.ndarray) -> np.ndarray:
    """Posed joint positions ``(T, 24, 3)`` of ``motion`` on ``rest_joints (24, 3)``."""
    rotations, translation = motion.to_torch(torch.float64)
    rest = torch.as_tensor(np.asarray(rest_joints), dtype=torch.float64)
    _, joints = forward_kinematics(rotations, rest, translation)
    return joints.numpy()


def plot_motion_preview(
    motion: Motion,
    rest_joints: torch.Tensor | np.ndarray,
    path: str | Path,
    num_frames: int = 6,
    dpi: int = 70,
) -> Path:
    """Write a PNG with ``num_frames`` evenly spaced frames, front view (X–Z, top row)
    and side view (Y–Z, bottom row), the ground trace of the pelvis in grey.

    Shapes:
        rest_joints ``(24, 3)`` metres.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    joints = skeleton_positions(motion, rest_joints)
    frames = np.unique(np.linspace(0, motion.num_frames - 1, num_frames).round().astype(int))
    fig, axes = plt.subplots(
        2, len(frames), figsize=(1.5 * len(frames), 3.6), squeeze=False, sharey="row"
    )
    low = joints[..., 2].min() - 0.05
    high = joints[..., 2].max() + 0.05
    for column, frame in enumerate(frames):
        centre = joints[frame, 0]
        for row, (h_axis, label) in enumerate(((0, "front"), (1, "side"))):
            ax = axes[row, column]
            ax.plot(joints[:, 0, h_axis] - centre[h_axis], joints[:, 0, 2], color="0.85", lw=0.8)
            for j, parent in enumerate(JOINT_PARENTS):
                if parent < 0:
                    continue
                left = JOINT_NAMES[j].startswith("L_")
                ax.plot(
                    joints[frame, [parent, j], h_axis] - centre[h_axis],
                    joints[frame, [parent, j], 2],
                    color="tab:red" if left else "tab:blue",
                    lw=1.6,
                )
            ax.set_xlim(-1.0, 1.0)
            ax.set_ylim(low, high)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if row == 0:
                ax.set_title(f"t={frame / motion.fps:.1f}s", fontsize=8)
            if column == 0:
                ax.set_ylabel(label, fontsize=8)
    fig.suptitle(motion.name or "motion", fontsize=9)
    fig.tight_layout(pad=0.3)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
