import typer
from typer.testing import CliRunner

from gnngarment.cli.body import register


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
        ["body", "--motion", "walk", "--joint-map", str(tmp_path / "map.json"), "--out",
         str(tmp_path)],
        ["body", "--motion", "walk", "--motion-up-axis", "w", "--out", str(tmp_path)],
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


def test_rest_body_is_exactly_the_frame_animate_expects(anny_body, tmp_path):
    """`body --rest` writes the rest mesh and joints that `animate` dresses a garment on:
    a garment modelled on that OBJ is in the right frame by construction."""
    import json

    import numpy as np

    from gnngarment.body.skeleton import JOINT_NAMES
    from gnngarment.geometry.mesh_io import load_mesh

    out = tmp_path / "rest"
    result = CliRunner().invoke(_app(), ["body", "--rest", "--shape", "tall_male", "--out",
                                         str(out)])
    assert result.exit_code == 0, result.output
    rest = anny_body.rest(anny_body.parse_shape("tall_male"))
    vertices, faces = load_mesh(out / "rest_body.obj")
    np.testing.assert_allclose(vertices, rest.vertices.numpy(), atol=2e-6)
    np.testing.assert_array_equal(faces, anny_body.faces)
    joints = json.loads((out / "rest_joints.json").read_text())
    assert list(joints) == list(JOINT_NAMES)
    np.testing.assert_allclose(np.array(list(joints.values())), rest.joints.numpy(), atol=2e-6)
    assert not list(out.glob("body_*.obj"))
