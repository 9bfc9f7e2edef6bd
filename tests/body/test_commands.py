import typer
from typer.testing import CliRunner

from gnngarment.body.commands import register


def _app():
    app = typer.Typer()
    register(app)
    return app


def test_motions_lists_library():
    result = CliRunner().invoke(_app(), ["motions"])
    assert result.exit_code == 0
    for name in ("walk", "sit_down", "dance"):
        assert name in result.output


def test_body_writes_obj_sequence_and_preview(anny_body, tmp_path):
    out = tmp_path / "out"
    result = CliRunner().invoke(
        _app(),
        ["body", "--motion", "wave", "--shape", "female", "--duration", "0.2", "--out", str(out)],
    )
    assert result.exit_code == 0, result.output
    objs = sorted(out.glob("body_*.obj"))
    assert len(objs) == 7 and (out / "skeleton.png").stat().st_size > 1000
    lines = objs[0].read_text().splitlines()
    assert sum(line.startswith("v ") for line in lines) == 13348
    assert sum(line.startswith("f ") for line in lines) == len(anny_body.faces)


def test_bad_input_exits_2_without_traceback(tmp_path):
    runner = CliRunner()
    cases = [
        ["body", "--motion", "moonwalk", "--out", str(tmp_path)],
        ["body", "--motion", str(tmp_path / "x.fbx"), "--out", str(tmp_path)],
        ["body", "--fps", "0", "--out", str(tmp_path)],
        [
            "body",
            "--model",
            "smpl",
            "--smpl-path",
            str(tmp_path / "none.pkl"),
            "--out",
            str(tmp_path),
        ],
    ]
    for args in cases:
        result = runner.invoke(_app(), args)
        assert result.exit_code == 2, (args, result.output)
        assert "error" in result.output and "Traceback" not in result.output
