"""Bad outfits get one line and exit 2 before any work, with nothing written."""

from __future__ import annotations

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
