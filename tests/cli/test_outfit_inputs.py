"""Bad outfits get one line and exit 2 before any work, with nothing written."""

from __future__ import annotations

import numpy as np
import trimesh
from typer.testing import CliRunner

from gnngarment.cli import app

runner = CliRunner()


def _garment(path):
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.icosphere(subdivisions=1, radius=0.2).export(path)
    return str(path)


def test_two_garments_with_one_name_are_refused(tmp_path) -> None:
    first, second = _garment(tmp_path / "a" / "top.obj"), _garment(tmp_path / "b" / "top.obj")
    out = tmp_path / "out"
    result = runner.invoke(app, ["animate", first, second, "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "top" in result.output and "share this name" in result.output
    assert not out.exists()


def test_layers_that_miss_a_garment_are_refused(tmp_path) -> None:
    top, trousers = _garment(tmp_path / "top.obj"), _garment(tmp_path / "trousers.obj")
    out = tmp_path / "out"
    result = runner.invoke(app, ["animate", top, trousers, "--layers", "top",
                                 "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "--layers top" in result.output and "every garment" in result.output
    assert not out.exists()


def test_a_missing_garment_file_is_refused(tmp_path) -> None:
    top = _garment(tmp_path / "top.obj")
    out = tmp_path / "out"
    result = runner.invoke(app, ["animate", top, str(tmp_path / "gone.obj"), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "gone.obj" in result.output
    assert not out.exists()


def test_a_garment_inside_the_body_is_refused(tmp_path, anny_body) -> None:
    """One garment of two sits inside the torso: refused by name, nothing written."""
    pelvis = anny_body.rest().joints[0].numpy()
    inside = tmp_path / "inside.obj"
    trimesh.creation.icosphere(subdivisions=2, radius=0.05).apply_translation(
        pelvis + np.array([0, 0, 0.15])).export(inside)
    top = _skirt(tmp_path / "skirt.obj", pelvis, 0.17, 0.3)
    out = tmp_path / "out"
    result = runner.invoke(app, ["animate", top, str(inside), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "inside.obj" in result.output
    assert not out.exists()


def _skirt(path, pelvis, waist: float, hem: float) -> str:
    from data_prep.garments.skirt import flared_skirt

    pos, faces = flared_skirt(300, waist_radius=waist, hem_radius=hem, length=0.4,
                              waist_height=pelvis[2] + 0.08, seed=1)
    pos[:, :2] += pelvis[:2]
    trimesh.Trimesh(pos, faces, process=False).export(path)
    return str(path)


def test_drape_settles_an_outfit_in_one_scene(tmp_path, anny_body) -> None:
    """`animate a b --drape`: both garments settled in one simulation, then animated."""
    import torch

    from gnngarment.model import GarmentDeformer
    from gnngarment.model.checkpoint import model_payload, save_checkpoint
    from tests.model.pairs import tiny_config

    torch.manual_seed(0)
    checkpoint = tmp_path / "model.pt"
    save_checkpoint(checkpoint, model_payload(GarmentDeformer(tiny_config())))
    pelvis = anny_body.rest().joints[0].numpy()
    inner = _skirt(tmp_path / "inner.obj", pelvis, 0.17, 0.30)
    outer = _skirt(tmp_path / "outer.obj", pelvis, 0.18, 0.31)
    out = tmp_path / "out"
    result = runner.invoke(app, ["animate", inner, outer, "--drape", "--checkpoint",
                                 str(checkpoint), "--out", str(out), "--duration", "0.1",
                                 "--format", "pc2", "--no-body"])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert text.count("2 garments of the outfit in one scene") == 2
    assert (out / "inner.pc2").is_file() and (out / "outer.pc2").is_file()
