"""``animate --lead-in`` (and ``attribute --lead-in``): a motion file starts from the rest
pose the garment is draped in, the exports include the lead-in, bad values exit 2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
import trimesh
from typer.testing import CliRunner

from data_prep.garments.skirt import flared_skirt
from gnngarment.cli import app
from gnngarment.inference.export import read_point_cache
from gnngarment.model import GarmentDeformer
from gnngarment.model.checkpoint import model_payload, save_checkpoint
from tests.model.pairs import tiny_config

runner = CliRunner()


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory, anny_body) -> dict[str, Path]:
    """A tiny model, a skirt on the rest body, and a 3-frame AMASS clip that starts
    posed (arms lowered 60°, the root turned), not at rest."""
    folder = tmp_path_factory.mktemp("lead_in")
    torch.manual_seed(0)
    checkpoint = folder / "model.pt"
    save_checkpoint(checkpoint, model_payload(GarmentDeformer(tiny_config())))
    pelvis = anny_body.rest().joints[0].numpy()
    pos, faces = flared_skirt(300, waist_radius=0.17, hem_radius=0.3, length=0.4,
                              waist_height=pelvis[2] + 0.08, seed=1)
    pos[:, :2] += pelvis[:2]
    garment = folder / "skirt.obj"
    trimesh.Trimesh(pos, faces, process=False).export(garment)
    poses = np.zeros((3, 72))
    poses[:, 2] = 0.3  # root yaw
    poses[:, 16 * 3 + 2], poses[:, 17 * 3 + 2] = -1.0, 1.0  # SMPL shoulders: arms down
    clip = folder / "clip.npz"
    np.savez(clip, poses=poses, trans=np.zeros((3, 3)), mocap_framerate=np.array(30.0))
    return {"checkpoint": checkpoint, "garment": garment, "clip": clip, "folder": folder}


def _animate(files, out: Path, *options: str):
    return runner.invoke(app, ["animate", str(files["garment"]), "--checkpoint",
                               str(files["checkpoint"]), "--out", str(out), "--motion",
                               str(files["clip"]), "--format", "pc2", *options])


def test_a_motion_file_gets_a_lead_in_from_the_rest_body(files, anny_body) -> None:
    out = files["folder"] / "led"
    result = _animate(files, out, "--lead-in", "0.2")
    assert result.exit_code == 0, result.output
    body = read_point_cache(out / "skirt_body.pc2")
    assert len(body) == 6 + 3  # round(0.2 s · 30 fps) lead-in frames, then the clip
    np.testing.assert_allclose(body[0], anny_body.rest().vertices.numpy(), atol=1e-5)
    assert "frames 0-5 are the 0.2 s lead-in" in " ".join(result.output.split())
    assert len(read_point_cache(out / "skirt.pc2")) == 9  # the garment has them too
    # Default for a file: 0.5 s; 0: the clip as loaded, starting posed.
    assert len(read_point_cache(_default(files) / "skirt_body.pc2")) == 15 + 3
    plain = files["folder"] / "plain"
    result = _animate(files, plain, "--lead-in", "0", "--no-body")
    assert result.exit_code == 0, result.output
    assert len(read_point_cache(plain / "skirt.pc2")) == 3
    assert "lead-in" not in result.output


def _default(files) -> Path:
    out = files["folder"] / "default"
    result = _animate(files, out, "--no-resolve-collisions")
    assert result.exit_code == 0, result.output
    return out


@pytest.mark.parametrize("value", ["-0.5", "nan", "inf", "10.5"])
def test_a_bad_lead_in_exits_2_before_any_loading(files, tmp_path, value) -> None:
    """Refused with one ``error:`` line before the checkpoint is even looked for."""
    result = runner.invoke(app, ["animate", str(files["garment"]), "--checkpoint",
                                 str(tmp_path / "absent.pt"), "--out", str(tmp_path / "o"),
                                 "--motion", str(files["clip"]), "--lead-in", value])
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: --lead-in must be a finite number")
    assert lines[0].endswith(f"got {float(value)}")
    result = runner.invoke(app, ["attribute", str(tmp_path / "absent.pt"),
                                 str(files["garment"]), "--out", str(tmp_path / "a"),
                                 "--lead-in", value])
    assert result.exit_code == 2 and "--lead-in must be a finite number" in result.output
