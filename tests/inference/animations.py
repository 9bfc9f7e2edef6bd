"""A tiny synthetic :class:`Animation` for export tests: a skirt-like tube on a cylinder
"body", skinned with random-but-valid per-frame weights (no body model, no network)."""

from __future__ import annotations

import numpy as np
import torch

from gnngarment.body.skeleton import forward_kinematics
from gnngarment.body.skinning import skin
from gnngarment.inference.animate import Animation
from tests.meshes import tube

#: A rough T-pose skeleton, Z up, metres, left = +X (SMPL order).
REST_JOINTS = np.array([
    [0.0, 0.0, 0.95], [0.09, 0.0, 0.88], [-0.09, 0.0, 0.88], [0.0, 0.0, 1.05],
    [0.09, 0.0, 0.50], [-0.09, 0.0, 0.50], [0.0, 0.0, 1.18], [0.09, 0.0, 0.10],
    [-0.09, 0.0, 0.10], [0.0, 0.0, 1.30], [0.09, -0.10, 0.03], [-0.09, -0.10, 0.03],
    [0.0, 0.0, 1.50], [0.07, 0.0, 1.45], [-0.07, 0.0, 1.45], [0.0, 0.0, 1.60],
    [0.18, 0.0, 1.43], [-0.18, 0.0, 1.43], [0.45, 0.0, 1.43], [-0.45, 0.0, 1.43],
    [0.70, 0.0, 1.43], [-0.70, 0.0, 1.43], [0.78, 0.0, 1.43], [-0.78, 0.0, 1.43],
])


def rest_body(rings: int = 30, sections: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """A closed cylinder "body" from the feet (z = 0) to the head (z = 1.7), radius 0.14,
    outward winding, with small triangles everywhere (like a real body mesh)."""
    pos, faces = tube(rings, sections, radius=0.14, height=1.7)
    bottom, top = len(pos), len(pos) + 1
    ring = np.arange(sections)
    following = (ring + 1) % sections
    last = (rings - 1) * sections
    caps = np.concatenate([np.stack([np.full(sections, bottom), following, ring], 1),
                           np.stack([np.full(sections, top), last + ring, last + following], 1)])
    pos = np.concatenate([pos, [[0.0, 0.0, 0.0], [0.0, 0.0, 1.7]]])
    return pos, np.concatenate([faces, caps])


def rest_garment(rings: int = 8, sections: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """A skirt-like open tube around the hips, z ∈ [0.55, 1.0], radius 0.22."""
    pos, faces = tube(rings, sections, radius=0.22, height=0.45)
    pos[:, 2] += 0.55
    return pos, faces


def joint_transforms(frames: int, amplitude: float = 0.6) -> np.ndarray:
    """``(T, 24, 4, 4)`` float32: legs swing, knees bend, the spine twists, the body
    turns and walks along −Y."""
    t = np.linspace(0.0, 2.0 * np.pi, frames, endpoint=False)
    rotations = np.zeros((frames, 24, 3))
    rotations[:, 0, 2] = 0.4 * np.sin(t)  # pelvis turn about Z
    rotations[:, 1, 0] = -amplitude * np.sin(t)  # L_hip swing
    rotations[:, 2, 0] = amplitude * np.sin(t)  # R_hip swing
    rotations[:, 4, 0] = 0.5 * amplitude * (1 + np.sin(t))  # L_knee
    rotations[:, 5, 0] = 0.5 * amplitude * (1 - np.sin(t))
    rotations[:, 3, 2] = 0.2 * np.sin(2 * t)  # spine twist
    rotations[:, 16, 1] = 1.2  # arms down
    rotations[:, 17, 1] = -1.2
    translation = np.stack([np.zeros(frames), -0.3 * t / (2 * np.pi), 0.02 * np.sin(2 * t)], 1)
    transforms, _ = forward_kinematics(torch.tensor(rotations), torch.tensor(REST_JOINTS),
                                       torch.tensor(translation))
    return transforms.numpy().astype(np.float32)


def per_frame_weights(pos: np.ndarray, frames: int, seed: int = 0) -> np.ndarray:
    """``(T, N, 24)`` softmax weights: nearest joints dominate, plus noise that drifts."""
    rng = np.random.default_rng(seed)
    distance = np.linalg.norm(pos[:, None] - REST_JOINTS[None], axis=-1)
    noise = rng.normal(size=(2, len(pos), 24))
    phase = np.linspace(0, np.pi, frames)[:, None, None]
    logits = -distance[None] / 0.08 + np.cos(phase) * noise[0] + np.sin(phase) * noise[1]
    logits -= logits.max(axis=-1, keepdims=True)
    weights = np.exp(logits)
    return (weights / weights.sum(axis=-1, keepdims=True)).astype(np.float32)


def synthetic_animation(frames: int = 6, rings: int = 8, sections: int = 20,
                        body_rings: int = 30, body_sections: int = 24, fps: float = 30.0,
                        seed: int = 0) -> Animation:
    """The whole fixture: garment posed with ``skin`` (weights, blend shapes, ``G``),
    body posed rigidly with its nearest joint (``body_rings × body_sections + 2``
    vertices)."""
    pos, faces = rest_garment(rings, sections)
    body_pos, body_faces = rest_body(body_rings, body_sections)
    transforms = joint_transforms(frames)
    weights = per_frame_weights(pos, frames, seed)
    t = np.arange(frames)[:, None, None]
    blend = (0.01 * np.sin(3 * pos[None, :, 2:3] + 0.5 * t)
             * np.array([1.0, 1.0, 0.0])).astype(np.float32)
    posed = skin(torch.tensor(pos, dtype=torch.float32), torch.tensor(blend),
                 torch.tensor(weights), torch.tensor(transforms)).numpy()
    nearest = np.linalg.norm(body_pos[:, None] - REST_JOINTS[None], axis=-1).argmin(axis=1)
    body_weights = np.eye(24, dtype=np.float32)[nearest]
    body = skin(torch.tensor(body_pos, dtype=torch.float32), None,
                torch.tensor(body_weights), torch.tensor(transforms)).numpy()
    return Animation(
        rest_pos=pos.astype(np.float32), faces=faces, posed=posed, weights=weights,
        blend_shapes=blend, joint_transforms=transforms,
        rest_joints=REST_JOINTS.astype(np.float32), body_vertices=body,
        body_faces=body_faces, fps=fps, seconds={})


def tube_uv(rings: int = 8, sections: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """A cylindrical unwrap of :func:`rest_garment`'s tube with one seam: ``uv
    (rings · (sections + 1), 2)``, ``u = s / sections``, ``v = r / (rings − 1)``, and
    per-corner ``uv_faces (F, 3)`` in the tube's face order. The column ``s = 0`` is
    used with ``u = 0`` on one side and ``u = 1`` on the other: ``rings`` seam vertices."""
    row = sections + 1
    s, r = np.meshgrid(np.arange(row), np.arange(rings))
    uv = np.stack([s.ravel() / sections, r.ravel() / (rings - 1)], axis=1)
    uv_faces = []
    for ring in range(rings - 1):
        for section in range(sections):
            a, b = ring * row + section, ring * row + section + 1  # b: no wrap, u may be 1
            uv_faces += [[a, b, b + row], [a, b + row, a + row]]
    return uv, np.array(uv_faces, dtype=np.int64)
