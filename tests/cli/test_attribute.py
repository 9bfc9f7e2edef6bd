"""``gnngarment attribute`` as a user runs it: input errors before any work."""

from __future__ import annotations

import numpy as np


def test_command_reports_a_missing_checkpoint(tmp_path) -> None:
    import typer
    from typer.testing import CliRunner

    from gnngarment.cli.attribute import register

    app = typer.Typer()
    register(app)

    @app.command("noop")
    def noop() -> None:  # a second command, so typer keeps "attribute" as a subcommand
        pass

    result = CliRunner().invoke(app, ["attribute", str(tmp_path / "none.pt"),
                                      str(tmp_path / "g.obj"), "--out", str(tmp_path)])
    assert result.exit_code == 2
    assert "checkpoint not found" in result.output
    result = CliRunner().invoke(app, ["attribute", "a.pt", "g.obj", "--out", "o",
                                      "--target", "face"])
    assert result.exit_code == 2 and "--target must be one of" in result.output


def test_a_garment_off_the_body_is_refused_before_attribution(tmp_path) -> None:
    """The placement check of ``animate`` runs here too: a garment 3 m beside the body
    exits 2 naming the file before integrated gradients run, and writes nothing."""
    import trimesh
    from typer.testing import CliRunner

    from gnngarment.cli import app
    from gnngarment.paths import SHIPPED_MODEL
    from tests.meshes import tube

    pos, faces = tube(12, 16)
    far = tmp_path / "far.obj"
    trimesh.Trimesh(pos + np.array([3.0, 0.0, 1.0]), faces, process=False).export(far)
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["attribute", str(SHIPPED_MODEL), str(far), "--out",
                                      str(out), "--n-steps", "2", "--duration", "0.2"])
    assert result.exit_code == 2, result.output
    assert "far.obj: the garment is not on the rest body" in " ".join(result.output.split())
    assert "Traceback" not in result.output and not out.exists()
