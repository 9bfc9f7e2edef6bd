"""Small garment–body pairs for model tests (synthetic joints and body features)."""

from __future__ import annotations

import numpy as np
import torch

from gnngarment.data.pair import GarmentBodyPair
from gnngarment.data.vertex_features import garment_vertex_features
from gnngarment.geometry import GarmentPreparationConfig, prepare_garment
from gnngarment.model import ModelConfig


def tiny_config(**overrides) -> ModelConfig:
    values = dict(garment_channels=[8, 16, 16], style_channels=[32, 16], body_channels=[32, 16],
                  motion_hidden=16, body_vertices=32, landmarks=16, window=3,
                  processor_channels=16)
    values.update(overrides)
    return ModelConfig(**values)


def make_pair(pos: np.ndarray, faces: np.ndarray, config: ModelConfig, seed: int = 0,
              levels: int = 3) -> GarmentBodyPair:
    rng = np.random.default_rng(seed)
    joints = rng.normal(scale=0.3, size=(24, 3))
    prepared = prepare_garment(pos, faces, GarmentPreparationConfig(
        levels=levels, landmarks=config.landmarks))
    return GarmentBodyPair(
        rest_pos=torch.tensor(pos, dtype=torch.float32),
        features=torch.from_numpy(garment_vertex_features(pos, faces, joints)),
        hierarchy=prepared.hierarchy,
        descriptor=torch.tensor(prepared.descriptor, dtype=torch.float32),
        body_distances=torch.tensor(rng.random((config.body_vertices, 24)), dtype=torch.float32),
        body_weights=nearest_joint_weights(pos, joints),
        joint_distances=beyond_nearest_joint(pos, joints),
    )


def nearest_joint_weights(pos: np.ndarray, joints: np.ndarray, scale: float = 0.1
                          ) -> torch.Tensor:
    """``(N, 24)`` stand-in body skinning weights: a softmax of minus the distance to the
    joints over ``scale`` metres (a function of position, so relabelling permutes it)."""
    distance = torch.cdist(torch.as_tensor(pos, dtype=torch.float64),
                           torch.as_tensor(joints, dtype=torch.float64))
    return torch.softmax(-distance / scale, dim=-1).float()


def beyond_nearest_joint(pos: np.ndarray, joints: np.ndarray) -> torch.Tensor:
    """``(N, 24)`` stand-in joint distances (metres): each joint's distance beyond the
    nearest joint (the body here is its joints)."""
    distance = torch.cdist(torch.as_tensor(pos, dtype=torch.float64),
                           torch.as_tensor(joints, dtype=torch.float64))
    return (distance - distance.min(dim=1, keepdim=True).values).float()


def frame_inputs(config: ModelConfig, pairs: int, frames: int, seed: int = 0,
                 rotate: bool = True) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Random motion/velocity windows and rigid joint transforms."""
    generator = torch.Generator().manual_seed(seed)
    motion = torch.randn(pairs, frames, config.window, 75, generator=generator) * 0.2
    velocity = torch.randn(pairs, frames, config.window, 3 * config.body_vertices,
                           generator=generator) * 0.1
    transforms = torch.eye(4).repeat(pairs, frames, 24, 1, 1)
    if rotate:
        angle = torch.rand(pairs, frames, 24, generator=generator)
        transforms[..., 0, 0] = torch.cos(angle)
        transforms[..., 0, 1] = -torch.sin(angle)
        transforms[..., 1, 0] = torch.sin(angle)
        transforms[..., 1, 1] = torch.cos(angle)
        transforms[..., :3, 3] = torch.randn(pairs, frames, 24, 3, generator=generator) * 0.05
    return motion, velocity, transforms
