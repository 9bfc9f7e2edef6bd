"""export_animation: every format into one folder, with a manifest."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gnngarment.geometry.mesh_io import read_obj, read_textured_obj
from gnngarment.inference.export import (
    GLTF_FROM_WORLD,
    evaluate_mesh_node,
    export_animation,
    read_glb,
    read_point_cache,
    read_point_cache_header,
)
from gnngarment.inference.export.gltf_reader import keyframe_times
from tests.inference.animations import synthetic_animation, tube_uv


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
    assert names == [f"body_{t:04d}.obj" for t in range(4)] + [
        f"garment_{t:04d}.obj" for t in range(4)]
    np.testing.assert_allclose(read_obj(out / "skirt_obj" / "garment_0002.obj")[0],
                               animation.posed[2], atol=1e-6)
    np.testing.assert_array_equal(read_point_cache(paths["pc2"]), animation.posed)
    assert read_point_cache_header(paths["pc2"]).start_frame == 0.0
    rest, faces = read_obj(paths["rest_obj"])
    np.testing.assert_allclose(rest, animation.rest_pos, atol=1e-6)
    np.testing.assert_array_equal(faces, animation.faces)
    assert read_point_cache(paths["body_pc2"]).shape == animation.body_vertices.shape
    manifest = json.loads(paths["manifest"].read_text())
    assert manifest["frames"] == 4 and manifest["first_frame"] == 0
    assert manifest["glb"]["start_time_s"] == 0.0 and manifest["uv"] is False
    assert manifest["glb"]["max_error_mm"] < 1e-3
    assert manifest["files"]["gif"] == "skirt.gif"
    # No temporary files left behind; the folder lock's (empty once released) `.lock`
    # stays, as flock locks must (deleting it would let two runs lock two files).
    assert [p.name for p in out.rglob(".*")] == [".lock"]


def test_subset_without_body(animation, tmp_path: Path) -> None:
    paths = export_animation(animation, tmp_path, "g", formats=("pc2", "obj"),
                             include_body=False, first_frame=1)
    assert set(paths) == {"pc2", "rest_obj", "obj", "manifest"}
    assert sorted(p.name for p in paths["obj"].iterdir())[0] == "garment_0001.obj"
    assert read_point_cache_header(paths["pc2"]).start_frame == 1.0


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"formats": ("fbx",)}, "formats must be"),
    ({"formats": ()}, "formats must be"),
    ({"name": "../up"}, "plain file stem"),
    ({"name": ""}, "plain file stem"),
    ({"first_frame": -1}, "first_frame"),
])
def test_bad_arguments(animation, tmp_path: Path, kwargs, message) -> None:
    arguments = {"name": "g", **kwargs}
    with pytest.raises(ValueError, match=message):
        export_animation(animation, tmp_path / "out", **arguments)
    assert not (tmp_path / "out").exists()


def glb_blender_frames(times: np.ndarray, fps: float) -> np.ndarray:
    """Scene frames Blender's glTF importer keys animation times at: ``time × fps``
    (io_scene_gltf2 ``blender/imp/animation_node.py``, ``animation_weight.py``:
    ``key[0] * fps``; no offset, the scene's frame range is left alone)."""
    return times * fps


def mesh_cache_sample(scene_frame: int, frame_start: int) -> int:
    """The PC2 sample Blender's Mesh Cache modifier shows (Time Mode Frame, Play Mode
    Scene, Frame Scale 1; ``MOD_meshcache.cc``): ``scene_frame − frame_start``; the
    header's start frame is ignored."""
    return scene_frame - frame_start


@pytest.mark.parametrize("first_frame", [0, 5])
def test_glb_obj_and_pc2_show_the_same_frame_at_the_same_frame_number(
        animation, tmp_path: Path, first_frame: int) -> None:
    paths = export_animation(animation, tmp_path, "g", formats=("obj", "pc2", "glb"),
                             include_body=False, first_frame=first_frame)
    count = len(animation.posed)
    numbers = sorted(int(p.stem.split("_")[1]) for p in paths["obj"].glob("garment_*.obj"))
    glb = read_glb(paths["glb"])
    times = keyframe_times(glb)
    header = read_point_cache_header(paths["pc2"])
    # Every format starts at first_frame and steps one frame per sample.
    assert numbers == list(range(first_frame, first_frame + count))
    assert (header.start_frame, header.sample_rate) == (first_frame, 1.0)
    np.testing.assert_allclose(glb_blender_frames(times, animation.fps),
                               np.arange(first_frame, first_frame + count), atol=1e-4)
    # ... and at scene frame first_frame + k all three show posed[k] (the docs' import
    # steps: Mesh Cache Frame Start = the manifest's first_frame).
    cache = read_point_cache(paths["pc2"])
    decoded = evaluate_mesh_node(glb, "g", times) @ GLTF_FROM_WORLD  # back to Z up
    for k in range(count):
        frame = first_frame + k
        obj = read_obj(paths["obj"] / f"garment_{frame:04d}.obj")[0]
        np.testing.assert_allclose(obj, animation.posed[k], atol=1e-6)
        np.testing.assert_array_equal(cache[mesh_cache_sample(frame, first_frame)],
                                      animation.posed[k])
        np.testing.assert_allclose(decoded[k], animation.posed[k], atol=1e-6)


def test_input_uvs_reach_the_garment_objs_and_the_glb(tmp_path: Path) -> None:
    animation = synthetic_animation(frames=3)
    animation.uv, animation.uv_faces = tube_uv()
    paths = export_animation(animation, tmp_path, "g", formats=("obj", "pc2", "glb"))
    for path in [paths["rest_obj"], *sorted(paths["obj"].glob("garment_*.obj"))]:
        mesh = read_textured_obj(path)
        assert len(mesh.pos) == len(animation.rest_pos)
        np.testing.assert_array_equal(mesh.uv_faces, animation.uv_faces)
        np.testing.assert_allclose(mesh.uv, animation.uv, atol=1e-6)
    assert read_textured_obj(paths["obj"] / "body_0000.obj").uv is None
    primitive = read_glb(paths["glb"]).document["meshes"][0]["primitives"][0]
    assert "TEXCOORD_0" in primitive["attributes"]
    manifest = json.loads(paths["manifest"].read_text())
    assert manifest["uv"] is True and manifest["glb"]["seam_vertices"] == 8


def test_a_shorter_rerun_leaves_no_frames_of_the_previous_export(animation,
                                                                 tmp_path: Path) -> None:
    """Frames of an earlier, longer export into the same folder (listed by its manifest)
    go; a file of the user's in that folder stays."""
    from dataclasses import replace

    export_animation(animation, tmp_path, "skirt", formats=("obj",))
    folder = tmp_path / "skirt_obj"
    (folder / "notes.txt").write_text("mine")
    short = replace(animation, posed=animation.posed[:2], body_vertices=animation.body_vertices[:2],
                    weights=animation.weights[:2], blend_shapes=animation.blend_shapes[:2],
                    joint_transforms=animation.joint_transforms[:2])
    export_animation(short, tmp_path, "skirt", formats=("obj",))
    assert sorted(p.name for p in folder.glob("garment_*.obj")) == ["garment_0000.obj",
                                                                    "garment_0001.obj"]
    assert sorted(p.name for p in folder.glob("body_*.obj")) == ["body_0000.obj",
                                                                 "body_0001.obj"]
    assert (folder / "notes.txt").read_text() == "mine"


def test_a_second_export_into_a_busy_folder_is_refused_and_stale_temporaries_go(
        animation, tmp_path: Path) -> None:
    from gnngarment.io.atomic import FolderBusyError, FolderLock

    with FolderLock(tmp_path, "export"), pytest.raises(FolderBusyError, match="another export"):
        export_animation(animation, tmp_path, "skirt", formats=("pc2",))
    assert not (tmp_path / "skirt.pc2").exists()
    # A killed export's temporary file, as its lock file recorded it; a user's file, and
    # one the user named like ours (not recorded: it stays).
    (tmp_path / "skirt_obj").mkdir()
    killed = tmp_path / "skirt_obj" / ".garment_0000.obj.0123abcd.tmp"
    killed.write_bytes(b"x" * 100)
    (tmp_path / ".lock").write_text("pid 1\ntemp skirt_obj/.garment_0000.obj.0123abcd.tmp\n")
    draft = tmp_path / ".draft.tmp"
    draft.write_text("mine")
    lookalike = tmp_path / "skirt_obj" / ".garment_0001.obj.0123abcd.tmp"
    lookalike.write_text("mine too")
    export_animation(animation, tmp_path, "skirt", formats=("obj",))
    assert not killed.exists() and draft.read_text() == "mine"
    assert lookalike.read_text() == "mine too"


def test_a_manifest_claiming_a_huge_export_does_not_hang_the_next_one(animation,
                                                                       tmp_path: Path) -> None:
    """Issue 38: a stale or foreign ``*_export.json`` claiming 10^8 frames made `animate`
    loop until killed; the next export now looks only at the frame files that exist."""
    import json

    (tmp_path / "skirt_obj").mkdir()
    (tmp_path / "skirt_export.json").write_text(json.dumps(
        {"name": "skirt", "first_frame": 0, "frames": 10**8}))
    stale = tmp_path / "skirt_obj" / "garment_5000000.obj"
    stale.write_text("an old frame\n")
    mine = tmp_path / "skirt_obj" / "notes_0001.obj"
    mine.write_text("the user's\n")
    export_animation(animation, tmp_path, "skirt", formats=("obj",))   # was: hours
    assert not stale.exists() and mine.read_text() == "the user's\n"


def test_files_of_a_killed_export_in_other_formats_do_not_stay_beside_a_new_one(
        animation, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 38: a killed `--format obj,pc2,glb` run left its skirt.glb beside the
    re-run's `--format obj,pc2` export. The pending manifest records the files an export
    is about to write; the next export removes those it does not write itself. Files
    the manifest does not list, or that are not named as ours, stay."""
    import gnngarment.inference.export.export as export_module

    real_write_obj_sequence = export_module.write_obj_sequence

    def killed(*args, **kwargs):  # the glb and pc2 are written, then the run dies
        raise KeyboardInterrupt

    monkeypatch.setattr(export_module, "write_obj_sequence", killed)
    with pytest.raises(KeyboardInterrupt):
        export_animation(animation, tmp_path, "skirt", formats=("obj", "pc2", "glb"))
    assert (tmp_path / "skirt.glb").is_file()
    monkeypatch.setattr(export_module, "write_obj_sequence", real_write_obj_sequence)
    (tmp_path / "skirt_notes.glb").write_text("mine")
    export_animation(animation, tmp_path, "skirt", formats=("obj", "pc2"))
    assert not (tmp_path / "skirt.glb").exists()
    assert (tmp_path / "skirt.pc2").is_file() and (tmp_path / "skirt_notes.glb").exists()
    # And an OBJ sequence goes when the next export writes none.
    export_animation(animation, tmp_path, "skirt", formats=("pc2",))
    assert not (tmp_path / "skirt_obj").exists()
    manifest = json.loads((tmp_path / "skirt_export.json").read_text())
    assert set(manifest["files"].values()) == {"skirt.pc2", "skirt_rest.obj",
                                                "skirt_body.pc2", "skirt_body.obj"}


def test_a_foreign_manifest_cannot_name_files_outside_our_export(animation,
                                                                  tmp_path: Path) -> None:
    user = tmp_path / "thesis.tex"
    user.write_text("mine")
    (tmp_path / "skirt_export.json").write_text(json.dumps(
        {"name": "skirt", "first_frame": 0, "frames": 4,
         "files": ["thesis.tex", "../outside.txt", "skirt.glb"]}))
    export_animation(animation, tmp_path, "skirt", formats=("pc2",))
    assert user.read_text() == "mine"
