"""CLOTH3D → prepared cache on synthetic sequences written in the CLOTH3D format."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from data_prep.cloth3d import write_info, write_obj, write_sequence, z_rotation
from data_prep.cloth3d_build import build_from_cloth3d, smpl_model_files
from gnngarment.body.cloth3d_motion import load_cloth3d_motion
from gnngarment.body.smpl_model import SMPLBodyModel
from gnngarment.cli import app
from gnngarment.data import PreparedDataset
from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
from gnngarment.data.cache import read_body
from tests.meshes import grid
from tests.smpl_files import synthetic_smpl, write_synthetic_smpl

BUILD = {"levels": 1, "landmarks": 8, "body_vertices": 16, "collision_points": 64}


def _sequence(folder: Path, smpl: Path, offset: float = 0.0, zrot: float = 0.0,
              gender: int = 0, stored_turn: float = 0.0, trans_in_cache: bool = False) -> None:
    """A sheet glued to the pelvis of SMPL posed the CLOTH3D way (root +90° about x, a
    knee bending, moving along x), written as CLOTH3D stores it: rest OBJ canonical, frames
    in the cache frame. ``stored_turn`` turns the stored OBJ about z (a template in the
    wrong orientation); ``trans_in_cache`` adds trans to the frames (a wrong frame)."""
    frames = 4
    poses = np.zeros((frames, 72))
    poses[:, 0] = np.pi / 2           # CLOTH3D's root x-rotation (Z up)
    poses[:, 3 * 4] = np.linspace(0, 0.4, frames)  # a knee bends
    trans = np.stack([np.linspace(0, 0.6, frames), np.zeros(frames), np.zeros(frames)], 1)
    info = {"poses": poses, "trans": trans, "shape": np.zeros(10), "gender": gender,
            "zrot": zrot, "outfit": {"Skirt": {"fabric": "cotton"}}}
    folder.mkdir(parents=True)
    # Pose the body the way the builder will, and wrap a small sheet around its pelvis.
    write_info(folder / "info.mat", info)
    body_model = SMPLBodyModel(smpl, gender=("female", "male")[gender])
    body = body_shape_inputs(body_model, np.zeros(10, np.float32), 16)
    posed = body_motion_inputs(body_model, np.zeros(10, np.float32),
                               load_cloth3d_motion(folder / "info.mat"), 16)
    pos, faces = grid(3, 4, spacing=0.05)
    rest = pos - pos.mean(0) + body.joints[0] + np.array([0, 0, offset])
    rest_h = np.concatenate([rest, np.ones((len(rest), 1))], 1)
    world = np.einsum("tab,nb->tna", posed.joint_transforms[:, 0], rest_h)[..., :3]
    shift = body.joints[0] + (trans - trans[0])
    cache = world - shift[:, None] + (trans[:, None] if trans_in_cache else 0)
    stored = (rest - body.joints[0]) @ z_rotation(stored_turn).T
    write_sequence(folder, info, {"Skirt": (stored, faces, cache.astype(np.float32))})
    write_obj(folder / "Skirt.obj", stored, faces)  # as CLOTH3D stores it, whatever the writer


def _male_smpl(path: Path) -> Path:
    """A second synthetic SMPL file, 20 % taller, so its use can be told apart."""
    data = synthetic_smpl(seed=1)
    data["v_template"] = data["v_template"] * 1.2
    np.savez(path, **data)
    return path


@pytest.fixture(scope="module")
def cloth3d(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("cloth3d")
    smpl = write_synthetic_smpl(root / "SMPL_FEMALE.npz")
    _sequence(root / "CLOTH3D" / "train" / "00001", smpl)
    _sequence(root / "CLOTH3D" / "train" / "00002", smpl, offset=1.5)   # far off the body
    _sequence(root / "CLOTH3D" / "test" / "00003", smpl)
    (root / "CLOTH3D" / "train" / "00004").mkdir()                     # no info.mat
    # The real sample's zrot: the template must be used as stored, not turned by −zrot.
    _sequence(root / "CLOTH3D" / "train" / "00005", smpl, zrot=2.813)
    # A template stored turned by 90°: on the body in every frame, yet inconsistent.
    _sequence(root / "CLOTH3D" / "train" / "00006", smpl, stored_turn=np.pi / 2)
    # Frames with trans baked in: on the body in frame 0 only.
    _sequence(root / "CLOTH3D" / "train" / "00007", smpl, trans_in_cache=True)
    return root / "CLOTH3D", smpl


def test_builds_a_cache_and_reports_what_it_left_out(cloth3d, tmp_path: Path) -> None:
    root, smpl = cloth3d
    report = build_from_cloth3d(root, smpl, tmp_path / "cache", **BUILD)
    assert report["splits"] == {"train": 2, "val": 0, "test": 1}
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


def test_rest_template_is_used_as_stored_whatever_zrot(cloth3d, tmp_path: Path) -> None:
    """Issue 13 item 4: with zrot = 2.813 the template used to be turned by −161°, so the
    cached rest mesh no longer matched frame 0 (up to 2× the sheet's size away)."""
    root, smpl = cloth3d
    build_from_cloth3d(root, smpl, tmp_path / "cache", **BUILD)
    dataset = PreparedDataset(tmp_path / "cache", "train", window=2)
    record = dataset.sequence("00005_Skirt")
    rest = dataset.garment_of("00005_Skirt").pair.rest_pos.numpy()
    np.testing.assert_allclose(record.positions[0], rest, atol=1e-3)


def test_turned_template_and_frames_off_the_body_later_are_left_out(
        cloth3d, tmp_path: Path) -> None:
    """A frame-0 body check passes both: a template turned by 90° still lies around the
    pelvis, and frames with trans baked in start on the body (trans_0 = 0)."""
    root, smpl = cloth3d
    report = build_from_cloth3d(root, smpl, tmp_path / "cache", **BUILD)
    skipped = report["skipped"]
    assert "turned -90° about z" in skipped["00006_Skirt"]
    assert "Skirt.obj" in skipped["00006_Skirt"]
    assert "from the body in frame 3" in skipped["00007_Skirt"]  # 0.6 m off by then
    assert not (tmp_path / "cache" / "sequences" / "00006_Skirt.npz").exists()
    assert not (tmp_path / "cache" / "sequences" / "00007_Skirt.npz").exists()


@pytest.fixture(scope="module")
def two_genders(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    root = tmp_path_factory.mktemp("genders")
    (root / "models").mkdir()
    female = write_synthetic_smpl(root / "models" / "SMPL_FEMALE.npz")
    male = _male_smpl(root / "models" / "SMPL_MALE.npz")
    _sequence(root / "cloth3d" / "00010", female, gender=0)
    _sequence(root / "cloth3d" / "00011", male, gender=1)
    return root / "cloth3d", female, male


def _joints(model: Path, gender: str) -> np.ndarray:
    return np.asarray(SMPLBodyModel(model, gender=gender).rest(np.zeros(10)).joints)


def test_each_sequence_is_posed_with_its_genders_model(two_genders, tmp_path: Path) -> None:
    """gender 0 → the female file, 1 → the male file (CLOTH3D's starter kit:
    ``'m' if gender else 'f'``); both garments land on their own body."""
    root, female, male = two_genders
    report = build_from_cloth3d(root, None, tmp_path / "cache", smpl_model_female=female,
                                smpl_model_male=male, **BUILD)
    assert report["splits"]["train"] == 2, report["skipped"]
    np.testing.assert_allclose(read_body(tmp_path / "cache", "00010_body").joints,
                               _joints(female, "female"), atol=1e-5)
    np.testing.assert_allclose(read_body(tmp_path / "cache", "00011_body").joints,
                               _joints(male, "male"), atol=1e-5)
    assert not np.allclose(_joints(female, "female"), _joints(male, "male"), atol=0.05)


def test_a_folder_serves_both_genders_and_one_file_still_serves_both(
        two_genders, tmp_path: Path) -> None:
    root, female, male = two_genders
    report = build_from_cloth3d(root, female.parent, tmp_path / "folder", **BUILD)
    assert report["smpl_models"] == {"female": str(female), "male": str(male)}
    np.testing.assert_allclose(read_body(tmp_path / "folder", "00011_body").joints,
                               _joints(male, "male"), atol=1e-5)
    # The old single --smpl-model FILE: one model for both (the male sheet is then off
    # its body, which the check reports, but nothing breaks).
    report = build_from_cloth3d(root, female, tmp_path / "single", **BUILD)
    assert report["smpl_models"] == {"female": str(female), "male": str(female)}
    assert "00010_Skirt" not in report["skipped"]


def test_smpl_model_files_rules(tmp_path: Path) -> None:
    folder = tmp_path / "models"
    folder.mkdir()
    official = folder / "basicmodel_m_lbs_10_207_0_v1.1.0.pkl"
    official.write_bytes(b"")
    female = write_synthetic_smpl(tmp_path / "f.npz")
    assert smpl_model_files(folder) == {"female": None, "male": official}
    assert smpl_model_files(folder, smpl_model_female=female) == {"female": female,
                                                                  "male": official}
    assert smpl_model_files(female) == {"female": female, "male": female}
    assert smpl_model_files() == {"female": None, "male": None}
    with pytest.raises(FileNotFoundError, match=r"absent\.pkl: SMPL model file not found"):
        smpl_model_files(None, smpl_model_male=tmp_path / "absent.pkl")
    with pytest.raises(FileNotFoundError, match="no female SMPL model here"):
        smpl_model_files(None, smpl_model_female=folder)


def test_a_gender_without_a_model_stops_before_any_work(two_genders, tmp_path: Path) -> None:
    root, female, _ = two_genders
    with pytest.raises(ValueError, match=r"00011/info\.mat: gender = 1 \(male\) but there is "
                                         r"no male SMPL model .*--smpl-model-male") as caught:
        build_from_cloth3d(root, None, tmp_path / "out", smpl_model_female=female, **BUILD)
    assert "\n" not in str(caught.value)
    assert not (tmp_path / "out").exists()
    only_female = tmp_path / "only_female"
    only_female.mkdir()
    (only_female / "SMPL_FEMALE.npz").write_bytes(female.read_bytes())
    with pytest.raises(ValueError, match=r"only_female holds none of SMPL_MALE\.pkl"):
        build_from_cloth3d(root, only_female, tmp_path / "out", **BUILD)
    assert not (tmp_path / "out").exists()


runner = CliRunner()


def _one_line_exit_2(result, *needles: str) -> None:
    assert result.exit_code == 2, result.output
    assert len([line for line in result.output.splitlines() if line.strip()]) == 1, result.output
    text = " ".join(result.output.split())
    assert "Traceback" not in result.output and all(n in text for n in needles), text


def test_cli_per_gender_models(two_genders, tmp_path: Path,
                               monkeypatch: pytest.MonkeyPatch) -> None:
    """``prepare --from-cloth3d`` takes --smpl-model-female/--smpl-model-male; a gender
    without a model, a missing file and no model at all are one line, exit 2, nothing
    written."""
    root, female, male = two_genders
    out = tmp_path / "out"
    base = ["prepare", "--from-cloth3d", str(root), "--output", str(out)]
    _one_line_exit_2(runner.invoke(app, [*base, "--smpl-model-female", str(female)]),
                     "00011", "no male SMPL model", "--smpl-model-male")
    _one_line_exit_2(runner.invoke(app, [*base, "--smpl-model-female", str(female),
                                         "--smpl-model-male", str(tmp_path / "nope.pkl")]),
                     "nope.pkl: SMPL model file not found")
    _one_line_exit_2(runner.invoke(app, base), "--smpl-model-female")
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not an smpl model")
    _one_line_exit_2(runner.invoke(app, [*base, "--smpl-model-female", str(female),
                                         "--smpl-model-male", str(bad)]), str(bad))
    assert not out.exists()
    # Both files reach the builder, each for its gender (a full build needs a real-size
    # SMPL model: the CLI's 512 body-feature vertices exceed the synthetic one's 96).
    import data_prep.cloth3d_build as build_module

    seen = {}
    monkeypatch.setattr(build_module, "build_from_cloth3d",
                        lambda *args, **kwargs: seen.update(args=args, kwargs=kwargs) or {})
    result = runner.invoke(app, [*base, "--smpl-model-female", str(female),
                                 "--smpl-model-male", str(male)])
    assert result.exit_code == 0, result.output
    assert seen["args"] == (root, None, out)
    assert seen["kwargs"] == {"smpl_model_female": female, "smpl_model_male": male}


def test_missing_folder_is_named(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="absent: CLOTH3D folder not found"):
        build_from_cloth3d(tmp_path / "absent", tmp_path / "smpl.npz", tmp_path / "out")
