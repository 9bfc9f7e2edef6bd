"""`gnngarment animate` as a user runs it: a garment file on the Anny body."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
import trimesh
from typer.testing import CliRunner

from data_prep.garments.skirt import flared_skirt
from gnngarment.cli import app
from gnngarment.geometry import load_mesh
from gnngarment.inference.export import read_point_cache
from gnngarment.model import GarmentDeformer
from gnngarment.model.checkpoint import model_payload, save_checkpoint
from tests.model.pairs import tiny_config

runner = CliRunner()


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory, anny_body) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("animate")
    torch.manual_seed(0)
    checkpoint = folder / "model.pt"
    save_checkpoint(checkpoint, model_payload(GarmentDeformer(tiny_config())))
    rest = anny_body.rest()
    pelvis = rest.joints[0].numpy()
    pos, faces = flared_skirt(400, waist_radius=0.17, hem_radius=0.3, length=0.4,
                              waist_height=pelvis[2] + 0.08, seed=1)
    pos[:, :2] += pelvis[:2]
    garment = folder / "skirt.obj"
    trimesh.Trimesh(pos, faces, process=False).export(garment)
    centimetres = folder / "skirt_cm.obj"
    trimesh.Trimesh(pos * 100, faces, process=False).export(centimetres)
    # A skirt whose waist is narrower than the body's: it cuts into the hips.
    tight, tight_faces = flared_skirt(400, waist_radius=0.12, hem_radius=0.22, length=0.35,
                                      waist_height=pelvis[2] + 0.05, seed=1)
    tight[:, :2] += pelvis[:2]
    tight_path = folder / "tight.obj"
    trimesh.Trimesh(tight, tight_faces, process=False).export(tight_path)
    return {"checkpoint": checkpoint, "garment": garment, "cm": centimetres, "folder": folder,
            "tight": tight_path}


def test_animate_writes_exports_in_the_input_vertex_order(files) -> None:
    out = files["folder"] / "out"
    result = runner.invoke(app, ["animate", str(files["garment"]), "--checkpoint",
                                 str(files["checkpoint"]), "--out", str(out), "--duration", "0.2",
                                 "--format", "obj,pc2", "--no-body"])
    assert result.exit_code == 0, result.output
    cache = read_point_cache(out / "skirt.pc2")
    pos, _ = load_mesh(files["garment"])
    assert cache.shape == (7, len(pos), 3)
    rest, _ = load_mesh(out / "skirt_rest.obj")
    np.testing.assert_allclose(rest, pos, atol=1e-6)
    assert len(list((out / "skirt_obj").glob("garment_*.obj"))) == 7


def test_centimetres_are_detected_and_refused_when_forced_to_metres(files) -> None:
    result = runner.invoke(app, ["animate", str(files["cm"]), "--checkpoint",
                                 str(files["checkpoint"]), "--out", str(files["folder"] / "x"),
                                 "--fix-units", "m", "--duration", "0.1", "--format", "obj"])
    assert result.exit_code == 2
    assert "not on the rest body" in " ".join(result.output.split())
    fixed = runner.invoke(app, ["animate", str(files["cm"]), "--checkpoint",
                                str(files["checkpoint"]), "--out", str(files["folder"] / "y"),
                                "--duration", "0.1", "--format", "obj", "--no-body"])
    assert fixed.exit_code == 0, fixed.output


def test_bad_inputs_exit_2(files, tmp_path: Path) -> None:
    cases = [
        (["animate", str(tmp_path / "absent.obj"), "--checkpoint", str(files["checkpoint"])],
         "absent.obj: file not found"),
        (["animate", str(files["garment"]), "--checkpoint", str(tmp_path / "none.pt")],
         "none.pt: checkpoint not found"),
        (["animate", str(files["garment"]), "--checkpoint", str(files["checkpoint"]),
          "--motion", "moonwalk"], "--motion moonwalk"),
        (["animate", str(files["garment"]), "--checkpoint", str(files["checkpoint"]),
          "--body-shape", "giant"], "--body-shape giant"),
    ]
    for arguments, message in cases:
        result = runner.invoke(app, arguments)
        assert result.exit_code == 2, (arguments, result.output)
        assert message in " ".join(result.output.split())


def test_collisions_are_resolved_unless_turned_off(files, anny_body) -> None:
    from gnngarment.geometry.signed_distance import refit_mesh, signed_distance_warp, warp_mesh

    pos, _ = load_mesh(files["tight"])
    depth = {}
    for flag in ("--resolve-collisions", "--no-resolve-collisions"):
        out = files["folder"] / flag.strip("-")
        result = runner.invoke(app, ["animate", str(files["tight"]), "--checkpoint",
                                     str(files["checkpoint"]), "--out", str(out),
                                     "--duration", "0.2", "--format", "pc2", flag,
                                     "--ignore-placement"])
        assert result.exit_code == 0, result.output
        assert ("collisions:" in result.output) == (flag == "--resolve-collisions")
        garment, body = read_point_cache(out / "tight.pc2"), read_point_cache(
            out / "tight_body.pc2")
        mesh = warp_mesh(body[0], anny_body.faces)
        depth[flag] = []
        for t in range(len(garment)):
            refit_mesh(mesh, body[t])
            depth[flag].append(signed_distance_warp(mesh, garment[t]).min())
        rest, _ = load_mesh(out / "tight_rest.obj")
        moved = np.abs(rest - pos).max()
        assert (moved > 1e-3) == (flag == "--resolve-collisions")
    assert min(depth["--resolve-collisions"]) >= 0.002 * 0.999
    assert min(depth["--no-resolve-collisions"]) < 0



def test_input_uvs_are_carried_into_the_obj_and_glb_exports(files) -> None:
    from gnngarment.geometry.mesh_io import read_textured_obj
    from gnngarment.inference.export import read_glb

    pos, faces = load_mesh(files["garment"])
    # A planar projection, one corner of vertex 0 given a UV of its own: a seam there.
    uv = np.concatenate([pos[:, :2] - pos[:, :2].min(axis=0), [[0.9, 0.9]]])
    uv_faces = faces.copy()
    face = int(np.flatnonzero((faces == 0).any(axis=1))[0])
    uv_faces[face][faces[face] == 0] = len(pos)
    corners = np.stack([faces, uv_faces], axis=-1) + 1
    textured = files["folder"] / "textured.obj"
    textured.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in pos.tolist())
                        + "".join(f"vt {u!r} {v!r}\n" for u, v in uv.tolist())
                        + "".join("f " + " ".join(f"{v}/{t}" for v, t in corner) + "\n"
                                  for corner in corners.tolist()))
    out = files["folder"] / "textured_out"
    result = runner.invoke(app, ["animate", str(textured), "--checkpoint",
                                 str(files["checkpoint"]), "--out", str(out), "--duration", "0.1",
                                 "--format", "obj,glb", "--no-body"])
    assert result.exit_code == 0, result.output
    frame = read_textured_obj(out / "textured_obj" / "garment_0000.obj")
    assert len(frame.pos) == len(pos)
    np.testing.assert_array_equal(frame.uv_faces, uv_faces)
    np.testing.assert_allclose(frame.uv, uv, atol=1e-6)
    document = read_glb(out / "textured.glb").document
    assert "TEXCOORD_0" in document["meshes"][0]["primitives"][0]["attributes"]
    assert document["meshes"][0]["extras"]["seamSources"] == [0]


def test_a_garment_is_fitted_from_the_body_it_was_made_on(files, anny_body) -> None:
    """The skirt modelled on a heavier body given as an SMPL-style file (Y up, facing +Z,
    centimetres): ``--source-body`` brings it onto the rest body at the distance it had
    from its own body; the placement checks then pass."""
    from gnngarment.inference.checks import Z_UP_FROM_Y_UP, _Surface

    heavy = anny_body.rest(anny_body.parse_shape("heavy_female"))
    source = heavy.vertices.numpy().astype(np.float64)
    pelvis = heavy.joints[0].numpy()
    pos, faces = flared_skirt(400, waist_radius=0.2, hem_radius=0.27, length=0.3,
                              waist_height=pelvis[2] + 0.08, seed=1)
    pos[:, :2] += pelvis[:2]
    gap = np.median(np.abs(_Surface(source, anny_body.faces).signed_distance(pos)))
    folder = files["folder"]
    trimesh.Trimesh(100 * pos @ Z_UP_FROM_Y_UP, faces, process=False).export(
        folder / "heavy_skirt.obj")
    trimesh.Trimesh(100 * source @ Z_UP_FROM_Y_UP, anny_body.faces, process=False).export(
        folder / "heavy_body.obj")
    out = folder / "fitted"
    result = runner.invoke(app, ["animate", str(folder / "heavy_skirt.obj"), "--source-body",
                                 str(folder / "heavy_body.obj"), "--checkpoint",
                                 str(files["checkpoint"]), "--out", str(out), "--duration",
                                 "0.1", "--format", "pc2", "--no-body",
                                 "--no-resolve-collisions"])
    assert result.exit_code == 0, result.output
    assert "fitted from the source body" in " ".join(result.output.split())
    rest, _ = load_mesh(out / "heavy_skirt_rest.obj")
    average = anny_body.rest()
    fitted_gap = np.median(np.abs(_Surface(average.vertices.numpy().astype(np.float64),
                                           anny_body.faces).signed_distance(rest)))
    assert gap < 0.08 and abs(fitted_gap - gap) < 0.01, (gap, fitted_gap)


def test_source_body_with_explicit_placement_or_a_bad_file_exits_2(files, tmp_path) -> None:
    base = ["animate", str(files["garment"]), "--checkpoint", str(files["checkpoint"]),
            "--out", str(tmp_path / "o")]
    cases = [
        (["--source-body", str(tmp_path / "nobody.obj")], "nobody.obj: file not found"),
        (["--source-body", str(files["garment"]), "--up-axis", "y"], "leave out --up-axis"),
        (["--scale", "-1"], "scale must be a finite number > 0"),
    ]
    for extra, message in cases:
        result = runner.invoke(app, base + extra)
        assert result.exit_code == 2, (extra, result.output)
        assert message in " ".join(result.output.split()), result.output


def test_drape_settles_the_garment_before_animating(files) -> None:
    """`--drape`: the rest garment written is the settled one (it moved, downwards on
    average: gravity), hanging from its waistband rather than sliding off the hips to
    the floor (it fell ~1 m before the band was held), and the command says how it
    went."""
    out = files["folder"] / "draped"
    result = runner.invoke(app, ["animate", str(files["garment"]), "--drape", "--checkpoint",
                                 str(files["checkpoint"]), "--out", str(out), "--duration",
                                 "0.1", "--format", "pc2", "--no-body"])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "draped on the rest body" in text and "hanging from its top band" in text
    given, _ = load_mesh(files["garment"])
    draped, _ = load_mesh(out / "skirt_rest.obj")
    assert 0.002 < np.linalg.norm(draped - given, axis=1).mean() < 0.15  # the flare sags
    assert (draped[:, 2] - given[:, 2]).mean() < 0


def test_inspect_says_an_undraped_garment_is_not_at_rest(files) -> None:
    """The flared skirt design (never simulated) sags as soon as it is simulated on the
    rest body: `inspect --rest-check` says it is not at rest and points to --drape."""
    import json

    result = runner.invoke(app, ["inspect", str(files["garment"]), "--rest-check", "--json"])
    assert result.exit_code == 0, result.output
    state = json.loads(result.output[result.output.index("{"):])["rest_check"]
    assert state["at_rest"] is False and state["mean_move_m"] > 0.003
    assert "animate --drape" in state["message"]


def test_an_unusable_output_folder_is_refused_before_any_work(files, tmp_path) -> None:
    existing = tmp_path / "a_file"
    existing.write_text("mine")
    result = runner.invoke(app, ["animate", str(files["garment"]), "--checkpoint",
                                 str(files["checkpoint"]), "--out", str(existing)])
    assert result.exit_code == 2, result.output
    assert f"--out {existing}" in " ".join(result.output.split())
    assert "animated" not in result.output and existing.read_text() == "mine"


def test_a_file_name_with_a_space_exports(files, tmp_path) -> None:
    import shutil

    spaced = tmp_path / "my skirt.obj"
    shutil.copy(files["garment"], spaced)
    result = runner.invoke(app, ["animate", str(spaced), "--checkpoint", str(files["checkpoint"]),
                                 "--out", str(tmp_path / "o"), "--duration", "0.1", "--format",
                                 "pc2", "--no-body"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "o" / "my_skirt.pc2").is_file()


def test_inspect_and_attribute_take_the_source_body(files, anny_body, tmp_path) -> None:
    """`inspect --source-body` reports the fit (units and up axis of an SMPL-style body
    file found: ×0.01, Y up); `attribute --source-body` runs on the fitted garment."""
    import json

    from gnngarment.inference.checks import Z_UP_FROM_Y_UP

    rest = anny_body.rest()
    pos, faces = load_mesh(files["garment"])
    body_file, garment_file = tmp_path / "body_cm.obj", tmp_path / "skirt_cm_y.obj"
    trimesh.Trimesh(100 * rest.vertices.numpy() @ Z_UP_FROM_Y_UP, anny_body.faces,
                    process=False).export(body_file)
    trimesh.Trimesh(100 * pos @ Z_UP_FROM_Y_UP, faces, process=False).export(garment_file)
    result = runner.invoke(app, ["inspect", str(garment_file), "--source-body", str(body_file),
                                 "--json"])
    assert result.exit_code == 0, result.output
    fit = json.loads(result.output[result.output.index("{"):])["fit"]
    assert abs(fit["scale"] - 0.01) < 2e-4
    np.testing.assert_allclose(fit["rotation"], Z_UP_FROM_Y_UP)
    heat = runner.invoke(app, ["attribute", str(files["checkpoint"]), str(garment_file),
                               "--source-body", str(body_file), "--out", str(tmp_path / "h"),
                               "--n-steps", "2", "--duration", "0.2"])
    assert heat.exit_code == 0, heat.output
    assert "fitted from the source body" in " ".join(heat.output.split())


def _tree(folder: Path) -> dict[str, tuple[int, int]]:
    """Every file under ``folder``: relative name → (size, mtime in ns)."""
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in folder.rglob("*") if p.is_file()}


@pytest.mark.slow
def test_a_second_run_into_a_busy_folder_is_refused_and_a_killed_one_leaves_nothing(
        files) -> None:
    """While one ``animate`` runs (from its first step, not only while it writes), a
    second into the same ``--out`` exits 2 naming the holder and touches nothing; the
    first is then killed with SIGKILL mid-export, and the next, shorter run leaves no
    temporary file and exactly its own frames (the manifest's count), none of the killed
    run's."""
    import json
    import os
    import signal
    import subprocess
    import sys
    import time

    from gnngarment.io.atomic import TEMP_SUFFIX
    from gnngarment.paths import REPOSITORY_ROOT

    out = files["folder"] / "busy"
    arguments = [str(files["garment"]), "--checkpoint", str(files["checkpoint"]), "--out",
                 str(out), "--format", "obj,pc2", "--no-resolve-collisions"]
    first = subprocess.Popen([sys.executable, "-m", "gnngarment.cli", "animate", *arguments,
                              "--duration", "20"], cwd=REPOSITORY_ROOT,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 300
        lock = out / ".lock"
        while not (lock.is_file() and lock.read_text().startswith(f"pid {first.pid}\n")):
            assert first.poll() is None and time.monotonic() < deadline
            time.sleep(0.02)
        before = _tree(out)
        second = runner.invoke(app, ["animate", *arguments, "--duration", "0.2"])
        assert second.exit_code == 2, second.output
        assert f"another export (pid {first.pid})" in " ".join(second.output.split())
        assert _tree(out) == before
        frames = out / "skirt_obj"
        while len(list(frames.glob("garment_*.obj"))) < 20:  # more than the next run's
            assert first.poll() is None and time.monotonic() < deadline
            time.sleep(0.005)
    finally:
        first.send_signal(signal.SIGKILL)
        first.wait()
    assert first.returncode == -signal.SIGKILL
    again = runner.invoke(app, ["animate", *arguments, "--duration", "0.2"])
    assert again.exit_code == 0, again.output
    assert not list(out.rglob(f"*{TEMP_SUFFIX}"))
    manifest = json.loads((out / "skirt_export.json").read_text())
    written = sorted(p.name for p in frames.glob("garment_*.obj"))
    assert len(written) == manifest["frames"] == 7, written[:3]
    assert os.path.getsize(out / "skirt.pc2") > 0


def animate_args(garment: Path, checkpoint: Path, out: Path, formats: str = "glb") -> list[str]:
    return ["animate", str(garment), "--checkpoint", str(checkpoint), "--out", str(out),
            "--duration", "0.2", "--format", formats, "--no-body"]


@pytest.mark.parametrize("place", ["the export's own name", "a symlink to the input",
                                   "the OBJ sequence folder", "an earlier export's file"])
def test_an_output_never_overwrites_the_input_garment(files, tmp_path: Path, place) -> None:
    """Issue 38: `animate OUT/skirt.glb --out OUT --format glb` replaced the user's garment
    with its own result. Refused before any work, the input as it was."""
    out = tmp_path / "out"
    out.mkdir()
    skirt = trimesh.load(files["garment"], process=False)
    if place == "the export's own name":
        garment, formats = out / "skirt.glb", "glb"
        skirt.export(garment)
    elif place == "a symlink to the input":
        garment, formats = tmp_path / "skirt.obj", "pc2"
        skirt.export(garment)
        (out / "skirt_rest.obj").symlink_to(garment)   # what pc2 writes beside it
    elif place == "the OBJ sequence folder":
        garment, formats = out / "skirt_obj" / "skirt.obj", "obj"
        garment.parent.mkdir()
        skirt.export(garment)
    else:  # an export of ours wrote skirt.glb; a pc2 export would remove it as stale
        garment, formats = out / "skirt.glb", "pc2"
        skirt.export(garment)
        (out / "skirt_export.json").write_text('{"files": {"glb": "skirt.glb"}}')
    before = garment.read_bytes()
    result = runner.invoke(app, animate_args(garment, files["checkpoint"], out, formats))
    assert result.exit_code == 2, result.output
    assert "would overwrite" in result.output or "replaces" in result.output, result.output
    assert garment.read_bytes() == before


def test_a_file_named_like_our_temporaries_is_the_users(files, tmp_path: Path) -> None:
    """Issue 38: `animate` deleted hand-placed `.x.0123abcd.tmp` files, also through a
    symlinked --out. Only temporaries a run of ours recorded are ever removed."""
    user = tmp_path / "user"
    user.mkdir()
    lookalikes = [".x.0123abcd.tmp", ".skirt.glb.0123abcd.tmp", ".manifest.json.0123abcd.tmp"]
    for name in lookalikes:
        (user / name).write_text("the user's")
    out = tmp_path / "linked"
    out.symlink_to(user)
    result = runner.invoke(app, animate_args(files["garment"], files["checkpoint"], out))
    assert result.exit_code == 0, result.output
    assert (user / "skirt.glb").is_file()
    for name in lookalikes:
        assert (user / name).read_text() == "the user's", name
