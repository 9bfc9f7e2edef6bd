"""glTF binary export: a skinned, morph-animated garment that reproduces the prediction,
valid per the Khronos validator."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from gnngarment.inference.export.gltf import GLTF_FROM_WORLD, write_glb
from gnngarment.inference.export.gltf_reader import evaluate_mesh_node, keyframe_times, read_glb
from tests.inference.animations import synthetic_animation, tube_uv

ROOT = Path(__file__).resolve().parents[3]
VALIDATOR_SCRIPT = Path(__file__).with_name("validate_gltf.mjs")


@pytest.fixture(scope="module")
def animation():
    return synthetic_animation(frames=6)


def khronos_report(path: Path) -> dict:
    """The Khronos glTF-Validator's report of ``path`` (npm devDependency)."""
    node = shutil.which("node")
    if node is None:
        pytest.fail("Node.js is needed to run the Khronos glTF validator: install node and "
                    "npm, then run `npm ci` in the repository root")
    if not (ROOT / "node_modules" / "gltf-validator").is_dir():
        pytest.fail(f"the Khronos glTF validator is not installed: run `npm ci` in {ROOT} "
                    f"(`make test` does this)")
    done = subprocess.run([node, str(VALIDATOR_SCRIPT), str(path)], capture_output=True,
                          text=True, cwd=ROOT, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


@pytest.mark.parametrize("options", [
    {},
    {"max_influences": 8, "morph_interpolation": "STEP", "include_body": True},
    {"max_influences": 3, "normals": False},
])
def test_glb_reproduces_the_prediction_and_passes_the_khronos_validator(
        animation, tmp_path: Path, options: dict) -> None:
    path = tmp_path / "skirt.glb"
    result = write_glb(animation, path, name="skirt", **options)
    # The file as a viewer evaluates it, decoded independently of the writer's arrays.
    glb = read_glb(path)
    decoded = evaluate_mesh_node(glb, "skirt")
    expected = animation.posed.astype(np.float64) @ GLTF_FROM_WORLD.T
    error = np.linalg.norm(decoded - expected, axis=-1)
    assert error.max() < 1e-6  # 1 µm: float32 rounding only
    assert result.max_error == pytest.approx(error.max(), abs=1e-12)
    assert result.ill_conditioned == 0
    assert result.skin_only_max_error > 100 * result.max_error  # the morphs do the work
    report = khronos_report(path)
    assert report["issues"]["numErrors"] == 0, report["issues"]["messages"]
    assert report["issues"]["numWarnings"] == 0, report["issues"]["messages"]
    assert report["issues"]["numInfos"] == report["issues"]["numHints"] == 0
    assert report["info"]["maxInfluences"] == (8 if options.get("max_influences") == 8 else 4)
    if options.get("include_body"):
        body = evaluate_mesh_node(glb, "body")
        np.testing.assert_allclose(body, animation.body_vertices @ GLTF_FROM_WORLD.T, atol=1e-6)


def test_document_structure(animation, tmp_path: Path) -> None:
    path = tmp_path / "g.glb"
    write_glb(animation, path, name="g")
    document = read_glb(path).document
    names = [node["name"] for node in document["nodes"]]
    assert names[:3] == ["pelvis", "L_hip", "R_hip"] and names[24] == "g"
    assert document["nodes"][0]["children"] == [1, 2, 3]
    primitive = document["meshes"][0]["primitives"][0]
    assert len(primitive["targets"]) == len(animation.posed)
    accessors = document["accessors"]
    for index in [primitive["attributes"]["POSITION"]] + [
            t["POSITION"] for t in primitive["targets"]]:
        assert "min" in accessors[index] and "max" in accessors[index]
    times = keyframe_times(read_glb(path))
    np.testing.assert_allclose(times, np.arange(6) / 30.0, rtol=1e-6)
    channels = document["animations"][0]["channels"]
    assert {c["target"]["path"] for c in channels} == {"translation", "rotation", "weights"}
    assert document["meshes"][0]["extras"]["targetNames"][0] == "frame_0000"


def test_between_frames_linear_morphs_blend_and_step_holds(animation, tmp_path: Path) -> None:
    halfway = np.array([0.5 / animation.fps])
    linear = evaluate_mesh_node(read_glb(write_glb(animation, tmp_path / "l.glb").path),
                                "garment", halfway)[0]
    step = evaluate_mesh_node(read_glb(write_glb(animation, tmp_path / "s.glb",
                                                 morph_interpolation="STEP").path),
                              "garment", halfway)[0]
    expected = 0.5 * (animation.posed[0] + animation.posed[1]) @ GLTF_FROM_WORLD.T
    # Cross-fading follows the prediction between frames more closely than holding.
    assert (np.linalg.norm(linear - expected, axis=-1).mean()
            < np.linalg.norm(step - expected, axis=-1).mean())


def test_bad_options_and_animation(animation, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="morph_interpolation"):
        write_glb(animation, tmp_path / "a.glb", morph_interpolation="CUBICSPLINE")
    with pytest.raises(ValueError, match="max_influences"):
        write_glb(animation, tmp_path / "a.glb", max_influences=9)
    broken = synthetic_animation(frames=2)
    broken.weights = broken.weights[:, :, :23]
    with pytest.raises(ValueError, match=r"weights must be \(2, 160, 24\)"):
        write_glb(broken, tmp_path / "a.glb")
    assert not list(tmp_path.iterdir())


def test_reader_agrees_with_a_file_written_by_trimesh(tmp_path: Path) -> None:
    import trimesh

    from tests.meshes import random_disk

    pos, faces = random_disk(30, seed=2)
    scene = trimesh.Scene()
    transform = trimesh.transformations.rotation_matrix(0.7, [0, 0, 1])
    transform[:3, 3] = [0.1, 0.2, 0.3]
    scene.add_geometry(trimesh.Trimesh(pos, faces, process=False), node_name="disk",
                       transform=transform)
    path = tmp_path / "disk.glb"
    path.write_bytes(scene.export(file_type="glb"))
    glb = read_glb(path)
    node = next(i for i, n in enumerate(glb.document["nodes"]) if "mesh" in n)
    decoded = evaluate_mesh_node(glb, node)[0]
    np.testing.assert_allclose(decoded, pos @ transform[:3, :3].T + transform[:3, 3],
                               atol=1e-6)


def test_reader_rejects_non_glb_files(tmp_path: Path) -> None:
    path = tmp_path / "x.glb"
    path.write_bytes(b"not a glb at all")
    with pytest.raises(ValueError, match="no 'glTF' magic"):
        read_glb(path)
    with pytest.raises(ValueError, match="cannot read"):
        read_glb(tmp_path / "missing.glb")


def test_input_uvs_become_texcoord_0_with_seams_split(tmp_path: Path) -> None:
    animation = synthetic_animation(frames=5)
    animation.uv, animation.uv_faces = tube_uv()
    count = len(animation.rest_pos)
    path = tmp_path / "skirt.glb"
    result = write_glb(animation, path, name="skirt")
    report = khronos_report(path)
    assert report["issues"]["numErrors"] == 0, report["issues"]["messages"]
    assert report["issues"]["numWarnings"] == 0, report["issues"]["messages"]
    # The one info: no texture of the (untextured) material reads TEXCOORD_0 yet.
    assert [(m["code"], m["pointer"]) for m in report["issues"]["messages"]] == [
        ("UNUSED_OBJECT", "/meshes/0/primitives/0/attributes/TEXCOORD_0")]

    glb = read_glb(path)
    mesh = glb.document["meshes"][0]
    primitive = mesh["primitives"][0]
    # glb vertex i < N is input vertex i; each seam duplicate names its input vertex.
    sources = np.concatenate([np.arange(count), mesh["extras"]["seamSources"]])
    assert result.seam_vertices == len(sources) - count == 8  # one per ring of the tube
    glb_faces = glb.accessor(primitive["indices"]).reshape(-1, 3).astype(np.int64)
    np.testing.assert_array_equal(sources[glb_faces], animation.faces)  # un-split = input
    texcoord = glb.accessor(primitive["attributes"]["TEXCOORD_0"]).astype(np.float64)
    assert texcoord.shape == (len(sources), 2)
    corner_uv = texcoord[glb_faces] * [1.0, -1.0] + [0.0, 1.0]  # back to OBJ's v up
    np.testing.assert_allclose(corner_uv, animation.uv[animation.uv_faces], atol=1e-7)

    # What a viewer shows reproduces the prediction at every input vertex and duplicate.
    decoded = evaluate_mesh_node(glb, "skirt")
    expected = animation.posed.astype(np.float64) @ GLTF_FROM_WORLD.T
    np.testing.assert_allclose(decoded, expected[:, sources], atol=1e-6)
    assert result.max_error < 1e-6
    normals = glb.accessor(primitive["attributes"]["NORMAL"])
    np.testing.assert_array_equal(normals, normals[sources])  # seams stay smooth


def test_first_frame_sets_the_time_blender_maps_to_that_frame(animation, tmp_path: Path
                                                              ) -> None:
    result = write_glb(animation, tmp_path / "g.glb", first_frame=3)
    times = keyframe_times(read_glb(result.path))
    # Blender's glTF importer keys scene frame `time × fps` (io_scene_gltf2,
    # blender/imp/animation_node.py and animation_weight.py: `key[0] * fps`).
    np.testing.assert_allclose(times * animation.fps, 3 + np.arange(len(animation.posed)),
                               atol=1e-4)
    assert result.start_time == pytest.approx(3 / animation.fps)
    assert result.max_error < 1e-6
    with pytest.raises(ValueError, match="first_frame"):
        write_glb(animation, tmp_path / "h.glb", first_frame=-1)
