"""The Blender add-on (``integrations/blender/gnngarment_import``): its bpy-free manifest
logic here, and the add-on itself in a Python that has ``bpy`` (Blender as a module) —
set ``GNNGARMENT_BLENDER_PYTHON`` to that interpreter, e.g. a venv with ``pip install
bpy`` (Python 3.11); without it those tests skip.

The exports are real ones (``export_animation``/``export_outfit`` on the synthetic
animation of ``tests/inference/animations.py``: a 160-vertex tube, a few frames), and
Blender's evaluated vertices are compared with the animation's ``posed`` at every frame.
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.inference.animations import synthetic_animation

ROOT = Path(__file__).resolve().parents[2]
BLENDER = ROOT / "integrations" / "blender"
CHECK_SCRIPT = Path(__file__).with_name("blender_check.py")


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


# The add-on's package imports bpy; its manifest module does not.
manifest = _load("gnngarment_blender_manifest", BLENDER / "gnngarment_import" / "manifest.py")
build_zip = _load("gnngarment_blender_build_zip", BLENDER / "build_zip.py").build_zip
ManifestError = manifest.ManifestError


# --------------------------------------------------------------------------- exports


@pytest.fixture(scope="module")
def exports(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """A single garment (30 fps, with body), an outfit (skirt + coat on one skeleton),
    and a 12.5 fps export starting at frame 3 without body."""
    from gnngarment.inference.export import export_animation
    from gnngarment.inference.export.outfit_export import export_outfit
    from gnngarment.inference.outfit import OutfitAnimation

    folder = tmp_path_factory.mktemp("blender")
    single = synthetic_animation(frames=5)
    export_animation(single, folder / "single", "skirt", formats=("glb", "pc2"))
    coat = synthetic_animation(frames=5, rings=6, sections=16, seed=1)
    coat.rest_pos[:, :2] *= 1.2  # a wider, shorter tube over the skirt
    coat.posed[..., :2] *= 1.2
    outfit = OutfitAnimation(names=["skirt", "coat"], animations=[single, coat], order=[0, 1],
                             relations=[], layer_stats={}, rest_layer_stats={},
                             penetration_raw={1: np.zeros(5)}, penetration={1: np.zeros(5)},
                             seconds={})
    export_outfit(outfit, folder / "outfit", "outfit", formats=("glb", "pc2"))
    odd = synthetic_animation(frames=4, fps=12.5, seed=2)
    export_animation(odd, folder / "odd", "dress", formats=("glb", "pc2"), include_body=False,
                     first_frame=3)
    return {"folder": folder, "single": single, "coat": coat, "odd": odd,
            "skirt_manifest": folder / "single" / "skirt_export.json",
            "outfit_manifest": folder / "outfit" / "outfit_export.json",
            "odd_manifest": folder / "odd" / "dress_export.json"}


def write_manifest(folder: Path, data: dict, name: str = "skirt_export.json") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(json.dumps(data))
    return path


GOOD = {"name": "skirt", "frames": 30, "fps": 30.0, "first_frame": 0,
        "garment_vertices": 160, "files": {"glb": "skirt.glb", "pc2": "skirt.pc2",
                                           "rest_obj": "skirt_rest.obj"}}


# --------------------------------------------------------------------------- manifest.py


def test_a_good_manifest_gives_the_rate_and_a_range_covering_every_frame(tmp_path) -> None:
    parsed = manifest.load_manifest(write_manifest(tmp_path, GOOD))
    assert (parsed.name, parsed.fps, parsed.frames, parsed.first_frame) == ("skirt", 30.0, 30, 0)
    assert parsed.garments == ("skirt",) and not parsed.is_outfit
    assert parsed.frame_range == (0, 29)  # 30 frames, both ends inclusive
    assert manifest.frame_range(3, 4) == (3, 6)
    assert manifest.blender_fps(parsed.fps) == (30, 1.0)
    assert parsed.body_name == "skirt_body"


def test_rates_blender_cannot_hold_as_an_integer_go_through_fps_base() -> None:
    for fps, expected in [(24, (24, 1.0)), (30.0, (30, 1.0)), (60.0, (60, 1.0))]:
        assert manifest.blender_fps(fps) == expected
    for fps in (29.97, 12.5, 0.5, 23.976):
        whole, base = manifest.blender_fps(fps)
        assert isinstance(whole, int) and whole >= 1
        assert whole / base == pytest.approx(fps, rel=1e-12)
        # Blender's glTF importer keys at t · fps · fps_base: what it must hold meanwhile.
        assert whole * manifest.importer_fps_base(base) == pytest.approx(fps, rel=1e-12)
    assert manifest.blender_fps(29.97) == (30, pytest.approx(1.001001, rel=1e-6))
    for bad in (0, -30.0, float("nan"), float("inf")):
        with pytest.raises(ManifestError, match="fps must be a positive number"):
            manifest.blender_fps(bad)


def test_a_real_export_manifest_parses_with_its_files(exports) -> None:
    single = manifest.load_manifest(exports["skirt_manifest"])
    assert (single.fps, single.frames, single.first_frame) == (30.0, 5, 0)
    assert single.garment_vertices == 160
    assert single.glb.name == "skirt.glb"
    caches = single.point_caches()
    assert [(m.name, m.obj.name, m.pc2.name, m.is_body) for m in caches] == [
        ("skirt", "skirt_rest.obj", "skirt.pc2", False),
        ("skirt_body", "skirt_body.obj", "skirt_body.pc2", True)]
    assert [m.name for m in single.point_caches(include_body=False)] == ["skirt"]
    points, start, rate, samples = manifest.read_pc2_header(caches[0].pc2)
    assert (points, start, rate, samples) == (160, 0.0, 1.0, 5)

    outfit = manifest.load_manifest(exports["outfit_manifest"])
    assert outfit.is_outfit and outfit.garments == ("skirt", "coat")
    assert outfit.glb.name == "outfit.glb"
    assert [(m.name, m.obj.name, m.pc2.name) for m in outfit.point_caches()] == [
        ("skirt", "skirt_rest.obj", "skirt.pc2"), ("coat", "coat_rest.obj", "coat.pc2"),
        ("outfit_body", "skirt_body.obj", "skirt_body.pc2")]

    odd = manifest.load_manifest(exports["odd_manifest"])
    assert (odd.fps, odd.first_frame, odd.frame_range) == (12.5, 3, (3, 6))
    assert manifest.read_pc2_header(odd.file("pc2"))[1] == 3.0  # header start = first_frame


@pytest.mark.parametrize(("change", "message"), [
    ({"fps": None}, "missing key 'fps'"),
    ({"files": None}, "missing key 'files'"),
    ({"fps": "30"}, "'fps' must be a positive number, got '30'"),
    ({"fps": 0}, "'fps' must be a positive number, got 0"),
    ({"fps": True}, "'fps' must be a positive number"),
    ({"frames": 2.5}, "'frames' must be a whole number ≥ 1, got 2.5"),
    ({"frames": 0}, "'frames' must be a whole number ≥ 1, got 0"),
    ({"first_frame": -1}, "'first_frame' must be a whole number ≥ 0"),
    ({"name": ""}, "'name' must be a non-empty string"),
    ({"files": ["skirt.glb"]}, "'files' must be an object of file names"),
    ({"files": {"glb": "../elsewhere.glb"}}, "must be a file name inside the export folder"),
    ({"files": {"glb": "/tmp/skirt.glb"}}, "must be a file name inside the export folder"),
    ({"garments": ["top", "top"]}, "names a garment twice"),
    ({"garments": []}, "'garments' must be a non-empty list of names"),
    ({"garment_vertices": "160"}, "'garment_vertices' must be a whole number"),
    ({"in_progress": True}, "did not finish"),
])
def test_a_bad_manifest_says_which_key_is_wrong(tmp_path, change, message) -> None:
    data = {**GOOD, **change}
    data = {key: value for key, value in data.items() if value is not None}
    with pytest.raises(ManifestError, match=message.replace("(", r"\(")):
        manifest.load_manifest(write_manifest(tmp_path, data))


def test_unreadable_manifests_and_missing_files_are_clear_errors(tmp_path) -> None:
    with pytest.raises(ManifestError, match="cannot read it"):
        manifest.load_manifest(tmp_path / "absent_export.json")
    broken = tmp_path / "broken_export.json"
    broken.write_text("{not json")
    with pytest.raises(ManifestError, match="not JSON"):
        manifest.load_manifest(broken)
    broken.write_text("[1, 2]")
    with pytest.raises(ManifestError, match="expected a JSON object, got list"):
        manifest.load_manifest(broken)
    parsed = manifest.load_manifest(write_manifest(tmp_path, GOOD))
    with pytest.raises(ManifestError, match="skirt.glb is listed but missing"):
        _ = parsed.glb
    with pytest.raises(ManifestError, match="no 'gif' file"):
        parsed.file("gif")
    not_pc2 = tmp_path / "x.pc2"
    not_pc2.write_bytes(b"POINTCACHE3\0" + bytes(20))
    with pytest.raises(ManifestError, match="not a PointCache2 file"):
        manifest.read_pc2_header(not_pc2)


def test_blender_suffixes_are_stripped_from_names() -> None:
    assert manifest.base_name("skirt.001") == "skirt"
    assert manifest.base_name("skirt") == "skirt"
    assert manifest.base_name("v1.2") == "v1.2"


def test_the_zip_holds_the_addon_package_only(tmp_path) -> None:
    import zipfile

    names = zipfile.ZipFile(build_zip(tmp_path / "addon.zip")).namelist()
    assert sorted(names) == ["gnngarment_import/__init__.py", "gnngarment_import/manifest.py"]


# --------------------------------------------------------------------------- in Blender


@pytest.fixture(scope="module")
def blender_python() -> str:
    """The interpreter named by GNNGARMENT_BLENDER_PYTHON, if it can import bpy."""
    path = os.environ.get("GNNGARMENT_BLENDER_PYTHON")
    if not path:
        pytest.skip("GNNGARMENT_BLENDER_PYTHON is unset (a Python with bpy: pip install bpy "
                    "into Python 3.11)")
    if not (Path(path).is_file() and os.access(path, os.X_OK)):
        pytest.skip(f"GNNGARMENT_BLENDER_PYTHON={path}: no such executable")
    probe = subprocess.run([path, "-c", "import bpy; print(bpy.app.version_string)"],
                           capture_output=True, text=True, timeout=120)
    if probe.returncode != 0:
        tail = (probe.stderr.strip().splitlines() or ["?"])[-1]
        pytest.skip(f"GNNGARMENT_BLENDER_PYTHON={path} cannot import bpy: {tail}")
    return path


@pytest.fixture(scope="module")
def blender(blender_python, exports, tmp_path_factory) -> dict:
    """What Blender shows after the add-on's import of each export (blender_check.py)."""
    folder = tmp_path_factory.mktemp("bpy")
    bad = {"missing_fps": {k: v for k, v in GOOD.items() if k != "fps"},
           "string_frames": {**GOOD, "frames": "30"},
           "in_progress": {"name": "skirt", "first_frame": 0, "frames": 5,
                           "in_progress": True, "files": ["skirt.glb"]}}
    config = {
        "zip": str(build_zip(folder / "gnngarment_import.zip")),
        "cases": {
            "single_glb": {"manifest": str(exports["skirt_manifest"]),
                           "use_point_cache": False, "include_body": True},
            "single_pc2": {"manifest": str(exports["skirt_manifest"]),
                           "use_point_cache": True, "include_body": True},
            "outfit_glb": {"manifest": str(exports["outfit_manifest"]),
                           "use_point_cache": False, "include_body": True},
            "outfit_pc2": {"manifest": str(exports["outfit_manifest"]),
                           "use_point_cache": True, "include_body": True},
            "odd_glb": {"manifest": str(exports["odd_manifest"]),
                        "use_point_cache": False, "include_body": True},
            "odd_pc2": {"manifest": str(exports["odd_manifest"]),
                        "use_point_cache": True, "include_body": True},
            "single_glb_no_body": {"manifest": str(exports["skirt_manifest"]),
                                   "use_point_cache": False, "include_body": False},
        },
        "bad": {label: str(write_manifest(folder / label, data))
                for label, data in bad.items()},
        "plain_glb": str(exports["folder"] / "single" / "skirt.glb"),
    }
    config_path, result_path = folder / "config.json", folder / "result.json"
    config_path.write_text(json.dumps(config))
    env = {**os.environ, "BLENDER_USER_SCRIPTS": str(folder / "user_scripts"),
           "OMP_NUM_THREADS": "1"}
    run = subprocess.run([blender_python, str(CHECK_SCRIPT), str(config_path),
                          str(result_path)], capture_output=True, text=True, timeout=300,
                         env=env, cwd=folder)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    return json.loads(result_path.read_text())


def objects(case: dict, kind: str | None = None) -> dict[str, dict]:
    return {obj["name"]: obj for obj in case["objects"] if kind is None or obj["type"] == kind}


def assert_plays_the_animation(mesh: dict, posed: np.ndarray) -> None:
    """Scene frame ``frame_start + k`` shows ``posed[k]`` (Z up, metres, vertex order
    kept), and the garment moves over the range."""
    shown = np.array(mesh["frames"])
    assert shown.shape == posed.shape, mesh["name"]
    np.testing.assert_allclose(shown, posed, atol=2e-5, err_msg=mesh["name"])
    assert np.abs(shown[-1] - shown[0]).max() > 0.05, f"{mesh['name']} does not move"


def assert_one_rig(case: dict, garments: list[str]) -> str:
    armatures = objects(case, "ARMATURE")
    assert len(armatures) == 1, list(armatures)
    (armature,) = armatures
    assert not objects(case, "EMPTY"), "the importer's leftover empties are removed"
    meshes = objects(case, "MESH")
    for garment in garments:
        mesh = meshes[garment]
        assert mesh["parent"] == armature
        assert [m["object"] for m in mesh["modifiers"] if m["type"] == "ARMATURE"] == [armature]
        assert mesh["shape_keys"] == len(mesh["frames"]) + 1  # Basis + one per frame
    return armature


def test_the_zip_installs_registers_and_unregisters(blender) -> None:
    assert blender["registered"] == {"operator": True, "file_handler": True, "menu": True}
    assert blender["unregistered"] == {"operator": False, "menu": False}


def test_blender_plays_a_single_glb_at_its_rate_over_its_frames(blender, exports) -> None:
    case, animation = blender["cases"]["single_glb"], exports["single"]
    assert case["outcome"] == ["FINISHED"]
    assert (case["fps"], case["fps_base"]) == (30, 1.0)
    assert (case["frame_start"], case["frame_end"]) == (0, 4)
    armature = assert_one_rig(case, ["skirt"])
    meshes = objects(case, "MESH")
    assert sorted(meshes) == ["skirt", "skirt_body"]
    assert meshes["skirt"]["vertices"] == 160 and meshes["skirt"]["smooth"]
    assert meshes["skirt"]["shape_key_action"] == [0.0, 4.0]  # keys on frames 0..4
    assert objects(case)[armature]["action"] == [0.0, 4.0]
    assert_plays_the_animation(meshes["skirt"], animation.posed)
    assert_plays_the_animation(meshes["skirt_body"], animation.body_vertices)
    assert {c for obj in case["objects"] for c in obj["collections"]} == {"skirt"}
    assert sorted(objects(blender["cases"]["single_glb_no_body"], "MESH")) == ["skirt"]


def test_blender_opens_the_outfit_as_one_rig(blender, exports) -> None:
    case = blender["cases"]["outfit_glb"]
    assert case["outcome"] == ["FINISHED"] and case["fps"] == 30
    assert (case["frame_start"], case["frame_end"]) == (0, 4)
    assert_one_rig(case, ["skirt", "coat"])
    meshes = objects(case, "MESH")
    assert sorted(meshes) == ["coat", "outfit_body", "skirt"]
    assert (meshes["skirt"]["vertices"], meshes["coat"]["vertices"]) == (160, 96)
    assert_plays_the_animation(meshes["skirt"], exports["single"].posed)
    assert_plays_the_animation(meshes["coat"], exports["coat"].posed)
    assert_plays_the_animation(meshes["outfit_body"], exports["single"].body_vertices)


def test_the_point_cache_path_moves_the_rest_obj(blender, exports) -> None:
    single, outfit = blender["cases"]["single_pc2"], blender["cases"]["outfit_pc2"]
    for case, expected in [(single, {"skirt": exports["single"].posed,
                                     "skirt_body": exports["single"].body_vertices}),
                           (outfit, {"skirt": exports["single"].posed,
                                     "coat": exports["coat"].posed,
                                     "outfit_body": exports["single"].body_vertices})]:
        assert case["outcome"] == ["FINISHED"] and case["fps"] == 30
        assert (case["frame_start"], case["frame_end"]) == (0, 4)
        assert sorted(objects(case)) == sorted(expected)  # no armature: meshes only
        for name, posed in expected.items():
            mesh = objects(case)[name]
            (cache,) = mesh["modifiers"]
            assert (cache["type"], cache["cache_format"], cache["frame_start"]) == (
                "MESH_CACHE", "PC2", 0.0)
            assert Path(cache["filepath"]).name == ("skirt_body.pc2" if "body" in name
                                                     else f"{name}.pc2")
            assert_plays_the_animation(mesh, posed)


def test_a_fractional_rate_and_a_later_first_frame_stay_frame_exact(blender, exports) -> None:
    """12.5 fps is render.fps 13 / fps_base 1.04; the glTF importer multiplies by
    fps_base, so the add-on holds 1/1.04 while it runs. Frames start at 3."""
    for label in ("odd_glb", "odd_pc2"):
        case = blender["cases"][label]
        assert case["outcome"] == ["FINISHED"]
        assert case["fps"] == 13 and case["fps"] / case["fps_base"] == pytest.approx(12.5)
        assert (case["frame_start"], case["frame_end"]) == (3, 6)
        assert sorted(objects(case, "MESH")) == ["dress"]
        assert_plays_the_animation(objects(case)["dress"], exports["odd"].posed)
    assert objects(blender["cases"]["odd_glb"])["dress"]["shape_key_action"] == [3.0, 6.0]
    assert objects(blender["cases"]["odd_pc2"])["dress"]["modifiers"][0]["frame_start"] == 3.0


def test_a_bad_manifest_is_reported_and_leaves_the_scene_alone(blender) -> None:
    expected = {"missing_fps": "missing key 'fps'",
                "string_frames": "'frames' must be a whole number ≥ 1, got '30'",
                "in_progress": "did not finish"}
    for label, message in expected.items():
        bad = blender["bad"][label]
        assert bad["outcome"] == ["ERROR"], label
        assert message in bad["message"], bad["message"]
        assert (bad["fps"], bad["objects"]) == (24, 0)  # factory scene untouched


def test_without_the_addon_a_30_fps_glb_lands_between_24_fps_frames(blender) -> None:
    """The pitfall: the glTF importer alone keys 5 frames at 30 fps over 0–3.2 of a
    24 fps scene (time · 24), not on frames 0–4."""
    plain = blender["plain_gltf"]
    assert plain["fps"] == 24
    assert all(action == [0.0, pytest.approx(3.2, abs=1e-5)] for action in plain["actions"])
