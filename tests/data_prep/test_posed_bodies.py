"""The posed body meshes of a synthetic cache come back only when they match the cached
body samples."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import torch

from data_prep.config import DataConfig
from data_prep.plan import plan_dataset
from data_prep.posed_bodies import synthetic_body_meshes
from gnngarment.body.anny_model import AnnyShape
from gnngarment.body.procedural import make_motion
from gnngarment.config import load_config
from gnngarment.data.cache import SequenceRecord, write_manifest, write_sequence
from gnngarment.paths import REPOSITORY_ROOT


def write_sequence_with_samples(root: Path, name: str, body_points: np.ndarray) -> None:
    frames = len(body_points)
    write_sequence(root, SequenceRecord(
        name=name, garment="g", body="b", motion="m", fps=30.0,
        positions=np.zeros((frames, 3, 3), np.float32),
        joint_transforms=np.tile(np.eye(4, dtype=np.float32), (frames, 24, 1, 1)),
        motion_features=np.zeros((frames, 75), np.float32),
        velocities=np.zeros((frames, 4, 3), np.float32), body_points=body_points,
        body_normals=np.zeros_like(body_points)))


def test_bodies_are_posed_again_and_checked_against_the_samples(tmp_path: Path,
                                                                 anny_body) -> None:
    config = load_config(REPOSITORY_ROOT / "configs" / "data" / "tiny.yaml", DataConfig)
    plan = plan_dataset(config)[0]
    motion = make_motion(plan.motion.motion, duration=config.motion_seconds, fps=config.fps,
                         seed=plan.motion.seed)
    with torch.no_grad():
        vertices = anny_body.pose(motion, AnnyShape(**plan.body.shape)).vertices.numpy()
    samples = anny_body.feature_vertex_indices(config.collision_points)
    write_sequence_with_samples(tmp_path, plan.name, vertices[:, samples])
    write_manifest(tmp_path, {"test": [plan.name]}, {},
                   extra={"config": asdict(config)})
    meshes = synthetic_body_meshes(tmp_path)
    posed, faces = meshes(plan.name)
    np.testing.assert_allclose(posed, vertices, atol=1e-5)
    np.testing.assert_array_equal(faces, anny_body.faces)
    assert meshes("not planned") is None
    # A cached body that is not the re-posed one gives no mesh (and says so).
    write_sequence_with_samples(tmp_path, plan.name, vertices[:, samples] + 0.01)
    with pytest.warns(UserWarning, match="does not match"):
        assert meshes(plan.name) is None
    # A cache with no synthetic build config (CLOTH3D's) has no meshes.
    write_manifest(tmp_path, {"test": [plan.name]}, {})
    assert synthetic_body_meshes(tmp_path)(plan.name) is None
