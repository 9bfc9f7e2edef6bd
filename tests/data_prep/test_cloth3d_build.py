"""CLOTH3D → prepared cache on a synthetic sequence written in the CLOTH3D format."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from data_prep.cloth3d import write_info, write_sequence
from data_prep.cloth3d_build import build_from_cloth3d
from gnngarment.body.motion_io import load_cloth3d_motion
from gnngarment.body.smpl_model import SMPLBodyModel
from gnngarment.data import PreparedDataset
from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
from tests.meshes import grid
from tests.smpl_files import write_synthetic_smpl


def _sequence(folder: Path, smpl: Path, offset: float) -> None:
    frames = 4
    poses = np.zeros((frames, 72))
    poses[:, 0] = np.pi / 2           # CLOTH3D's root x-rotation (Z up)
    poses[:, 3 * 4] = np.linspace(0, 0.4, frames)  # a knee bends
    trans = np.stack([np.linspace(0, 0.1, frames), np.zeros(frames), np.zeros(frames)], 1)
    info = {"poses": poses, "trans": trans, "shape": np.zeros(10), "gender": 0, "zrot": 0.0,
            "outfit": {"Skirt": {"fabric": "cotton"}}}
    folder.mkdir(parents=True)
    # Pose the body the way the builder will, and wrap a small sheet around its pelvis.
    write_info(folder / "info.mat", info)
    body_model = SMPLBodyModel(smpl, gender="female")
    body = body_shape_inputs(body_model, np.zeros(10, np.float32), 16)
    posed = body_motion_inputs(body_model, np.zeros(10, np.float32),
                               load_cloth3d_motion(folder / "info.mat"), 16)
    pos, faces = grid(3, 4, spacing=0.05)
    rest = pos - pos.mean(0) + body.joints[0] + np.array([0, 0, offset])
    rest_h = np.concatenate([rest, np.ones((len(rest), 1))], 1)
    world = np.einsum("tab,nb->tna", posed.joint_transforms[:, 0], rest_h)[..., :3]
    shift = body.joints[0] + (trans - trans[0])
    write_sequence(folder, info, {"Skirt": (rest - body.joints[0], faces,
                                            (world - shift[:, None]).astype(np.float32))})


@pytest.fixture(scope="module")
def cloth3d(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("cloth3d")
    smpl = write_synthetic_smpl(root / "SMPL_FEMALE.npz")
    _sequence(root / "CLOTH3D" / "train" / "00001", smpl, offset=0.0)
    _sequence(root / "CLOTH3D" / "train" / "00002", smpl, offset=1.5)   # far off the body
    _sequence(root / "CLOTH3D" / "test" / "00003", smpl, offset=0.0)
    (root / "CLOTH3D" / "train" / "00004").mkdir()                     # no info.mat
    return root / "CLOTH3D", smpl


def test_builds_a_cache_and_reports_what_it_left_out(cloth3d, tmp_path: Path) -> None:
    root, smpl = cloth3d
    report = build_from_cloth3d(root, smpl, tmp_path / "cache", levels=1, landmarks=8,
                                body_vertices=16, collision_points=64)
    assert report["splits"] == {"train": 1, "val": 0, "test": 1}
    assert any("00002" in name and "frame conventions" in why
               for name, why in report["skipped"].items())
    assert any("00004" in name for name in report["skipped"])
    dataset = PreparedDataset(tmp_path / "cache", "train", window=2)
    record = dataset.sequence("00001_Skirt")
    assert record.positions.shape == (4, 12, 3)
    # The garment follows the pelvis: frame 0 equals its rest placement on the body.
    garment = dataset.garment_of("00001_Skirt")
    np.testing.assert_allclose(record.positions[0], garment.pair.rest_pos.numpy(), atol=1e-3)
    batch = dataset.batch([("00001_Skirt", np.array([1, 3]))])
    assert batch.target.shape == (24, 3)


def test_missing_folder_is_named(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="absent: CLOTH3D folder not found"):
        build_from_cloth3d(tmp_path / "absent", tmp_path / "smpl.npz", tmp_path / "out")
