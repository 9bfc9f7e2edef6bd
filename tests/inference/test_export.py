"""export_animation: every format into one folder, with a manifest."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gnngarment.geometry.mesh_io import read_obj
from gnngarment.inference.export import export_animation, read_point_cache, read_point_cache_header
from tests.inference.animations import synthetic_animation


@pytest.fixture(scope="module")
def animation():
    return synthetic_animation(frames=4)


def test_everything_lands_in_one_documented_layout(animation, tmp_path: Path) -> None:
    stages = []
    paths = export_animation(animation, tmp_path / "out", "skirt",
                             progress=lambda stage, done, total: stages.append(stage))
    out = tmp_path / "out"
    assert {k: p.relative_to(out).as_posix() for k, p in paths.items()} == {
        "glb": "skirt.glb", "pc2": "skirt.pc2", "rest_obj": "skirt_rest.obj",
        "body_pc2": "skirt_body.pc2", "body_obj": "skirt_body.obj", "obj": "skirt_obj",
        "gif": "skirt.gif", "manifest": "skirt_export.json"}
    assert set(stages) == {"glb", "pc2", "obj", "gif"}
    names = sorted(p.name for p in (out / "skirt_obj").iterdir())
    assert names == [f"body_{t:04d}.obj" for t in range(1, 5)] + [
        f"garment_{t:04d}.obj" for t in range(1, 5)]
    np.testing.assert_allclose(read_obj(out / "skirt_obj" / "garment_0003.obj")[0],
                               animation.posed[2], atol=1e-6)
    np.testing.assert_array_equal(read_point_cache(paths["pc2"]), animation.posed)
    assert read_point_cache_header(paths["pc2"]).start_frame == 1.0
    rest, faces = read_obj(paths["rest_obj"])
    np.testing.assert_allclose(rest, animation.rest_pos, atol=1e-6)
    np.testing.assert_array_equal(faces, animation.faces)
    assert read_point_cache(paths["body_pc2"]).shape == animation.body_vertices.shape
    manifest = json.loads(paths["manifest"].read_text())
    assert manifest["frames"] == 4 and manifest["first_frame"] == 1
    assert manifest["glb"]["max_error_mm"] < 1e-3
    assert manifest["files"]["gif"] == "skirt.gif"
    assert not [p for p in out.rglob(".*")]  # no temporary files left behind


def test_subset_without_body(animation, tmp_path: Path) -> None:
    paths = export_animation(animation, tmp_path, "g", formats=("pc2", "obj"),
                             include_body=False, first_frame=0)
    assert set(paths) == {"pc2", "rest_obj", "obj", "manifest"}
    assert sorted(p.name for p in paths["obj"].iterdir())[0] == "garment_0000.obj"
    assert read_point_cache_header(paths["pc2"]).start_frame == 0.0


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"formats": ("fbx",)}, "formats must be"),
    ({"formats": ()}, "formats must be"),
    ({"name": "../up"}, "plain file stem"),
    ({"name": ""}, "plain file stem"),
])
def test_bad_arguments(animation, tmp_path: Path, kwargs, message) -> None:
    arguments = {"name": "g", **kwargs}
    with pytest.raises(ValueError, match=message):
        export_animation(animation, tmp_path / "out", **arguments)
    assert not (tmp_path / "out").exists()
