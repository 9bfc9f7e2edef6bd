"""A tiny prepared cache written through the real cache writers, with a learnable but
simulator-free ground truth (for fast data/training/evaluation tests; the Newton-made
demo set is exercised by the slow end-to-end test)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from gnngarment.body.skinning import skin
from gnngarment.data import (
    BodyRecord,
    GarmentRecord,
    SequenceRecord,
    topology_key,
    write_body,
    write_garment,
    write_manifest,
    write_sequence,
    write_topology,
)
from gnngarment.geometry import GarmentPreparationConfig, prepare_garment
from tests.meshes import random_disk, tube


def _rotation_z(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    matrix = np.zeros((*angle.shape, 4, 4), dtype=np.float32)
    matrix[..., 0, 0], matrix[..., 0, 1], matrix[..., 1, 0], matrix[..., 1, 1] = c, -s, s, c
    matrix[..., 2, 2] = matrix[..., 3, 3] = 1
    return matrix


def build_synthetic_cache(root: Path, frames: int = 8, landmarks: int = 16,
                          body_vertices: int = 32, levels: int = 2) -> Path:
    """Two garment types × two bodies × two motions; split by garment.

    Ground truth: every vertex follows the pelvis-like joint 0, which rotates about z,
    plus a sag that grows with the rotation speed — a deformation the model can learn.
    """
    rng = np.random.default_rng(0)
    meshes = {"disk": random_disk(90, 4), "tube": tube(6, 10, radius=0.25)}
    garments_by_type = {"disk": ["disk_a"], "tube": ["tube_a", "tube_b"]}
    bodies = {}
    for b in range(2):
        joints = rng.normal(scale=0.3, size=(24, 3)).astype(np.float32)
        distances = rng.random((body_vertices, 24)).astype(np.float32) * (1 + b)
        bodies[f"body{b}"] = joints
        write_body(root, BodyRecord(name=f"body{b}", joints=joints, distances=distances,
                                    subset=np.arange(body_vertices)))
    sequences, splits = {}, {"train": [], "val": [], "test": []}
    for garment_type, names in garments_by_type.items():
        for g, garment_name in enumerate(names):
            pos, faces = meshes[garment_type]
            pos = pos * (1 + 0.1 * g)
            prepared = prepare_garment(pos, faces, GarmentPreparationConfig(
                levels=levels, landmarks=landmarks))
            key = topology_key(faces)
            write_topology(root, key, prepared.hierarchy)
            for body in bodies:
                name = f"{garment_name}_{body}"
                write_garment(root, GarmentRecord(
                    name=name, rest_pos=pos.astype(np.float32), faces=faces,
                    descriptor=prepared.descriptor, topology=key, garment_type=garment_type,
                    body=body, body_weights=np.eye(24, dtype=np.float32)[np.zeros(len(pos), int)],
                    # Joint 0's region is the garment itself; every other joint is 1 m away.
                    joint_distances=np.where(np.arange(24) == 0, 0.0,
                                             1.0)[None].repeat(len(pos), 0)))
                for m, speed in enumerate((0.1, 0.25)):
                    angle = speed * np.arange(frames)
                    transforms = np.repeat(_rotation_z(angle)[:, None], 24, axis=1)
                    rest = torch.tensor(pos, dtype=torch.float32)
                    weights = torch.zeros(len(pos), 24)
                    weights[:, 0] = 1
                    posed = skin(rest.expand(frames, -1, -1), None,
                                 weights.expand(frames, -1, -1), torch.from_numpy(transforms))
                    positions = posed.numpy() - np.array([0, 0, 0.02 * speed], np.float32)
                    motion = np.zeros((frames, 75), np.float32)
                    motion[:, 2] = angle
                    motion[1:, 72] = speed
                    velocities = np.full((frames, body_vertices, 3), speed, np.float32)
                    floor = np.stack(np.meshgrid(np.linspace(-1, 1, 12),
                                                 np.linspace(-1, 1, 12)), -1).reshape(-1, 2)
                    points = np.column_stack([floor, np.full(len(floor), -0.5)])
                    normals = np.tile([0.0, 0.0, 1.0], (len(points), 1))
                    sequence = f"{name}_m{m}"
                    write_sequence(root, SequenceRecord(
                        name=sequence, garment=name, body=body, motion=f"spin{m}", fps=30.0,
                        positions=positions, joint_transforms=transforms,
                        motion_features=motion, velocities=velocities,
                        body_points=np.repeat(points[None], frames, 0),
                        body_normals=np.repeat(normals[None], frames, 0)))
                    sequences[sequence] = {"garment": name, "body": body, "motion": f"spin{m}",
                                           "frames": frames, "garment_type": garment_type}
                    split = ("test" if garment_name == "tube_b"
                             else "val" if (body, m) == ("body1", 1) else "train")
                    splits[split].append(sequence)
    write_manifest(root, splits, sequences)
    return root
