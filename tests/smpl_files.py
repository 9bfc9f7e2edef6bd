"""A small synthetic model file in the SMPL format (the licensed one is never shipped),
so the real SMPL loading path is exercised in tests."""

import pickle
from pathlib import Path

import numpy as np

from gnngarment.body.skeleton import JOINT_PARENTS


def synthetic_smpl(n_per_joint=4, seed=0):
    """A tiny SMPL-format model: a Y-up stick figure with a few vertices per joint."""
    rng = np.random.default_rng(seed)
    joints = np.zeros((24, 3))
    offsets = {  # child offset from parent, metres, Y up, facing +Z, left = +X
        1: (0.09, -0.08, 0), 2: (-0.09, -0.08, 0), 3: (0, 0.1, 0), 4: (0, -0.38, 0),
        5: (0, -0.38, 0), 6: (0, 0.13, 0), 7: (0, -0.4, 0), 8: (0, -0.4, 0), 9: (0, 0.05, 0),
        10: (0, -0.05, 0.12), 11: (0, -0.05, 0.12), 12: (0, 0.22, 0), 13: (0.08, 0.12, 0),
        14: (-0.08, 0.12, 0), 15: (0, 0.09, 0), 16: (0.1, 0.02, 0), 17: (-0.1, 0.02, 0),
        18: (0.26, 0, 0), 19: (-0.26, 0, 0), 20: (0.25, 0, 0), 21: (-0.25, 0, 0),
        22: (0.08, 0, 0), 23: (-0.08, 0, 0),
    }  # fmt: skip
    for j in range(1, 24):
        joints[j] = joints[JOINT_PARENTS[j]] + offsets[j]
    vertices = np.repeat(joints, n_per_joint, axis=0) + 0.02 * rng.standard_normal(
        (24 * n_per_joint, 3)
    )
    n = len(vertices)
    owner = np.repeat(np.arange(24), n_per_joint)
    weights = np.zeros((n, 24))
    weights[np.arange(n), owner] = 1.0
    regressor = np.zeros((24, n))
    regressor[owner, np.arange(n)] = 1.0 / n_per_joint
    # Joint = mean of its vertices; shift vertices so that mean lands exactly on the joint.
    for j in range(24):
        vertices[owner == j] += joints[j] - vertices[owner == j].mean(0)
    faces = np.array([[i, i + 1, i + 2] for i in range(0, n - 2, 3)], dtype=np.int64)
    kintree = np.array(
        [[4294967295 if p < 0 else p for p in JOINT_PARENTS], list(range(24))], dtype=np.int64
    )
    return {
        "v_template": vertices,
        "shapedirs": 0.01 * rng.standard_normal((n, 3, 10)),
        "posedirs": np.zeros((n, 3, 207)),
        "J_regressor": regressor,
        "weights": weights,
        "kintree_table": kintree,
        "f": faces,
    }


def write_synthetic_smpl(path: Path) -> Path:
    """Write :func:`synthetic_smpl` as ``.pkl`` or ``.npz`` (by the suffix)."""
    data = synthetic_smpl()
    if path.suffix == ".pkl":
        with open(path, "wb") as stream:
            pickle.dump(data, stream)
    else:
        np.savez(path, **data)
    return path
