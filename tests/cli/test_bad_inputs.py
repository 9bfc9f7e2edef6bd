"""Hostile inputs to every command (issue "Hostile inputs and interrupted work"): each is
refused with exit code 2 and one line naming the file or option, no traceback, before
any long work, and nothing is written or changed under the output folder.

Every case is a row of :data:`CASES`: the command line, a fragment the error must
contain, and the text files to write for it. ``$name`` in them is replaced by a path:
an input made once per module (:func:`inputs`), ``$work`` (this case's folder),
``$out`` (an output folder holding a user's files) or ``$new`` (a folder that does not
exist yet).
"""

from __future__ import annotations

import builtins
import json
import zipfile
from dataclasses import asdict
from pathlib import Path
from string import Template
from typing import NamedTuple

import numpy as np
import pytest
import torch
import trimesh
from typer.testing import CliRunner

from gnngarment.cli import app
from gnngarment.paths import SHIPPED_MODEL
from tests.meshes import tube
from tests.model.pairs import tiny_config

runner = CliRunner()

#: Files already in the output folder, which every refused command leaves as they are: a
#: user's file, a user's hidden ``*.tmp`` one, and one named like the temporary file a
#: killed write of ours leaves (a started build or export would remove that one).
USER_FILES = {"notes.txt": "the user's own notes\n", ".draft.tmp": "the user's own draft\n",
              ".manifest.json.0123abcd.tmp": "a killed write's leftover\n"}


class Payload:
    """Unpickling this runs code: it creates the file ``marker`` (must never exist)."""

    def __init__(self, marker: Path) -> None:
        self.marker = str(marker)

    def __reduce__(self):
        return builtins.open, (self.marker, "w")


#: A BVH skeleton with the usual Mixamo/cgspeed names (as tests/body/test_bvh_motion.py).
BVH_JOINTS = [
    ("Hips", None, (0, 0, 0)),
    ("LeftUpLeg", "Hips", (1.6, -2, 0.8)), ("LeftLeg", "LeftUpLeg", (0, -7, 0)),
    ("LeftFoot", "LeftLeg", (0, -7, 0)), ("LeftToeBase", "LeftFoot", (0, -0.5, 2)),
    ("RightUpLeg", "Hips", (-1.6, -2, 0.8)), ("RightLeg", "RightUpLeg", (0, -7, 0)),
    ("RightFoot", "RightLeg", (0, -7, 0)), ("RightToeBase", "RightFoot", (0, -0.5, 2)),
    ("Spine", "Hips", (0, 2, 0)), ("Spine1", "Spine", (0, 2, 0)), ("Spine2", "Spine1", (0, 2, 0)),
    ("Neck", "Spine2", (0, 2, 0)), ("Head", "Neck", (0, 1, 0)),
    ("LeftShoulder", "Spine2", (0, 2, 0)), ("LeftArm", "LeftShoulder", (3, 0, 0)),
    ("LeftForeArm", "LeftArm", (5, 0, 0)), ("LeftHand", "LeftForeArm", (4, 0, 0)),
    ("RightShoulder", "Spine2", (0, 2, 0)), ("RightArm", "RightShoulder", (-3, 0, 0)),
    ("RightForeArm", "RightArm", (-5, 0, 0)), ("RightHand", "RightForeArm", (-4, 0, 0)),
]  # fmt: skip


def bvh_text(frames: int = 4) -> str:
    children: dict[str | None, list[str]] = {}
    for name, parent, _ in BVH_JOINTS:
        children.setdefault(parent, []).append(name)
    offsets = {name: offset for name, _, offset in BVH_JOINTS}
    lines: list[str] = []

    def emit(name: str, depth: int) -> None:
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if depth == 0 else 'JOINT'} {name}\n{pad}{{")
        lines.append(f"{pad}  OFFSET {' '.join(str(v) for v in offsets[name])}")
        position = "Xposition Yposition Zposition " if depth == 0 else ""
        lines.append(f"{pad}  CHANNELS {6 if depth == 0 else 3} {position}"
                     "Zrotation Yrotation Xrotation")
        for child in children.get(name, []):
            emit(child, depth + 1)
        if not children.get(name):
            lines.append(f"{pad}  End Site\n{pad}  {{\n{pad}    OFFSET 0 0 0\n{pad}  }}")
        lines.append(f"{pad}}}")

    emit("Hips", 0)
    row = " ".join(["0"] * (3 + 3 * len(BVH_JOINTS)))
    return ("HIERARCHY\n" + "\n".join(lines) + f"\nMOTION\nFrames: {frames}\n"
            "Frame Time: 0.0333333\n" + "\n".join([row] * frames) + "\n")


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory, anny_body) -> dict[str, Path]:
    """The (read-only) hostile and good input files, made once."""
    from data_prep.garments.skirt import flared_skirt
    from gnngarment.model import GarmentDeformer
    from gnngarment.model.checkpoint import model_payload, save_checkpoint
    from tests.synthetic_cache import build_synthetic_cache

    folder = tmp_path_factory.mktemp("inputs")
    paths: dict[str, Path] = {"inputs": folder, "shipped": SHIPPED_MODEL}

    def write(name: str, content: str | bytes) -> None:
        paths[name.replace(".", "_")] = path = folder / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)

    # Garments: a skirt on the average body, and broken meshes.
    pelvis = anny_body.rest().joints[0].numpy()
    pos, faces = flared_skirt(300, waist_radius=0.17, hem_radius=0.3, length=0.4,
                              waist_height=pelvis[2] + 0.08, seed=1)
    pos[:, :2] += pelvis[:2]
    trimesh.Trimesh(pos, faces, process=False).export(folder / "skirt.obj")
    paths["skirt"] = folder / "skirt.obj"
    far, far_faces = tube(8, 12)
    far += np.array([3.0, 0.0, 1.0])  # 3 m beside the body
    trimesh.Trimesh(far, far_faces, process=False).export(folder / "far.obj")
    paths["far"] = folder / "far.obj"
    write("empty.obj", "")
    write("garbage.obj", "this is not a mesh\n\x00\x01 at all\n")
    write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n")
    write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n")
    write("huge_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 99999999999999999999 2 3\n")
    write("huge_float_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1e30 2 3\n")
    write("negative_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -9 2 3\n")
    write("nofaces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    write("binary.ply", bytes(range(256)) * 8)
    write("binary.glb", b"glTF" + bytes(range(256)) * 4)
    # Checkpoints.
    torch.manual_seed(0)
    payload = model_payload(GarmentDeformer(tiny_config()))
    save_checkpoint(folder / "tiny.pt", payload)
    paths["tiny"] = folder / "tiny.pt"
    whole = (folder / "tiny.pt").read_bytes()
    # Its hash key removed and a weight scaled: a tampered file that no longer says so.
    tampered = torch.load(folder / "tiny.pt", weights_only=True)
    del tampered["content_hash"]
    first = next(iter(tampered["model_state"]))
    tampered["model_state"][first] = tampered["model_state"][first] * 1000
    torch.save(tampered, folder / "unhashed.pt")
    paths["unhashed_pt"] = folder / "unhashed.pt"
    write("garbage.pt", b"not a checkpoint at all" * 10)
    write("truncated.pt", whole[: len(whole) // 2])
    with zipfile.ZipFile(folder / "other.pt", "w") as archive:
        archive.writestr("readme.txt", "a zip of something else")
    paths["other_pt"] = folder / "other.pt"
    save_checkpoint(folder / "nokeys.pt", {"epoch": 3})
    paths["nokeys_pt"] = folder / "nokeys.pt"
    other = model_payload(GarmentDeformer(tiny_config(processor_channels=8)))
    save_checkpoint(folder / "otherarch.pt", {**payload, "model_state": other["model_state"]})
    paths["otherarch_pt"] = folder / "otherarch.pt"
    paths["marker"] = folder / "code_ran"
    torch.save({"format_version": 1, "model_config": Payload(paths["marker"])},
               folder / "code.pt")
    paths["code_pt"] = folder / "code.pt"
    # Motions and body shapes.
    write("clip.bvh", bvh_text())
    text = bvh_text()
    write("short.bvh", text[: text.index("MOTION") - 40])
    np.savez(folder / "wrong.npz", poses=np.zeros((4, 70)), trans=np.zeros((4, 3)),
             mocap_framerate=np.array(30.0))
    paths["wrong_npz"] = folder / "wrong.npz"
    # CLOTH3D info.mat files whose fields have the wrong types (issue 38).
    import scipy.io

    mat_fields = {"poses": np.zeros((72, 4)), "trans": np.zeros((3, 4)), "zrot": 0.0}
    for name, change in {"poses_string": {"poses": "abc"}, "poses_struct": {"poses": {"a": 1}},
                         "trans_cell": {"trans": np.array(["a", "b"], dtype=object)},
                         "poses_nan": {"poses": np.full((72, 4), np.nan)}}.items():
        (folder / name).mkdir()
        scipy.io.savemat(folder / name / "info.mat", {**mat_fields, **change})
        paths[f"{name}_mat"] = folder / name / "info.mat"
    write("map.json", json.dumps({"L_hipp": "LeftUpLeg"}))
    write("shape_key.json", json.dumps({"heigth": 0.5}))
    write("shape_list.json", json.dumps([0.5, 0.5]))
    write("shape_range.yaml", "height: 2.0\n")
    # SMPL models: an .npz with a pickled object array (loading it must not run it).
    np.savez(folder / "smpl_code.npz", v_template=np.array([Payload(paths["marker"])],
                                                           dtype=object))
    paths["smpl_code_npz"] = folder / "smpl_code.npz"
    paths["cache"] = build_synthetic_cache(folder / "cache", frames=4)
    return paths


#: The tiny model of tests/model/pairs.py as a YAML flow mapping.
TINY_MODEL = json.dumps(asdict(tiny_config()))
TRAIN = ("data: $cache\noutput: $out\nmodel: " + TINY_MODEL + "\nepochs: 1\n"
         "pairs_per_batch: 2\nframes_per_pair: 2\nthreads: 1\n")
#: A dataset config that is valid (configs/data/tiny.yaml, its output the case's).
DATA = """output: $out
seed: 0
garment_types: [skirt, tshirt, trousers]
garments: 4
garment_vertices: [300, 420]
bodies: 3
body_presets: [average]
motions: [walk, squat, arm_raise]
motion_seconds: 0.2
fps: 30.0
motions_per_pair: 1
fabrics: [cotton, silk]
body_vertices: 64
collision_points: 512
levels: 2
landmarks: 32
simulation: configs/simulation.yaml
settle_frames: 0
drape_frames: 30
"""


def data_config(**changes: str) -> str:
    """:data:`DATA` with ``key: value`` lines replaced."""
    lines = DATA.splitlines()
    for key, value in changes.items():
        lines = [f"{key}: {value}" if line.startswith(f"{key}:") else line for line in lines]
    return "\n".join(lines) + "\n"


class Case(NamedTuple):
    args: list[str]
    expect: str  # a fragment of the error line ($names replaced)
    write: dict[str, str] | None = None  # files made in $work (text, $names replaced)


ANIMATE = ["animate", "$skirt", "--out", "$out", "--duration", "0.2"]
BODY = ["body", "--out", "$out", "--duration", "0.2"]
ATTRIBUTE = ["attribute", "$shipped", "$skirt", "--out", "$out", "--n-steps", "2",
             "--duration", "0.2"]
EVALUATE = ["evaluate", "--checkpoint", "$tiny", "--data", "$cache", "--no-spurious"]

#: Nine aliases to nine aliases ... six levels deep: 9**6 values once expanded.
ALIAS_BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{name}: &{name} [{', '.join(['*' + inner] * 9)}]\n"
    for inner, name in zip("abcde", "bcdef", strict=True))

CASES: dict[str, Case] = {
    # ---- inspect: garment meshes and configs -------------------------------------------------
    "inspect-missing": Case(
        ["inspect", "$work/absent.obj"],
        "$work/absent.obj: file not found"),
    "inspect-empty": Case(
        ["inspect", "$empty_obj"],
        "$empty_obj: the file holds no faces"),
    "inspect-garbage": Case(
        ["inspect", "$garbage_obj"],
        "$garbage_obj: the file holds no faces"),
    "inspect-inf": Case(
        ["inspect", "$inf_obj"],
        "$inf_obj: invalid mesh: 1 vertices have NaN/inf coordinates"),
    "inspect-face-range": Case(
        ["inspect", "$range_obj"],
        "$range_obj: invalid mesh: 1 faces index vertices outside 0..2"),
    "inspect-huge-index": Case(
        ["inspect", "$huge_index_obj"], "$huge_index_obj: cannot read OBJ file (face index"),
    "inspect-huge-float-index": Case(
        ["inspect", "$huge_float_index_obj"],
        "$huge_float_index_obj: cannot read OBJ file (face index"),
    "animate-huge-index": Case(
        ["animate", "$huge_index_obj", "--out", "$out", "--duration", "0.2"],
        "$huge_index_obj: cannot read OBJ file (face index"),
    "animate-negative-index": Case(
        ["animate", "$negative_index_obj", "--out", "$out", "--duration", "0.2"],
        "$negative_index_obj: invalid mesh"),
    "inspect-no-faces": Case(
        ["inspect", "$nofaces_obj"],
        "$nofaces_obj: the file holds no faces"),
    "inspect-binary-ply": Case(
        ["inspect", "$binary_ply"],
        "$binary_ply: cannot read PLY file"),
    "inspect-binary-glb": Case(
        ["inspect", "$binary_glb"],
        "$binary_glb: cannot read GLB file"),
    "inspect-folder": Case(
        ["inspect", "$inputs"],
        "$inputs: "),
    "inspect-config-list": Case(
        ["inspect", "$skirt", "--config", "$work/garment.yaml"],
        "$work/garment.yaml: expected a mapping of settings, got a list",
        {"garment.yaml": "- levels\n- 2\n"}),
    "inspect-source-body-garbage": Case(
        ["inspect", "$skirt", "--source-body", "$garbage_obj"],
        "$garbage_obj: the file holds no faces"),
    # ---- animate: meshes, checkpoints, motions, body shapes, options, placement --------------
    "animate-nan-mesh": Case(
        ["animate", "$nan_obj", "--out", "$out"],
        "$nan_obj: invalid mesh: 1 vertices have NaN/inf coordinates"),
    "animate-no-faces": Case(
        ["animate", "$nofaces_obj", "--out", "$out"],
        "$nofaces_obj: the file holds no faces"),
    "animate-ckpt-garbage": Case(
        [*ANIMATE, "--checkpoint", "$garbage_pt"],
        "$garbage_pt: not a readable gnngarment checkpoint"),
    "animate-ckpt-unhashed": Case(
        [*ANIMATE, "--checkpoint", "$unhashed_pt"],
        "$unhashed_pt: has no content hash"),
    "evaluate-ckpt-unhashed": Case(
        ["evaluate", "--checkpoint", "$unhashed_pt", "--data", "$cache", "--no-spurious"],
        "$unhashed_pt: has no content hash"),
    "animate-ckpt-truncated": Case(
        [*ANIMATE, "--checkpoint", "$truncated_pt"],
        "$truncated_pt: not a readable gnngarment checkpoint (PytorchStreamReader failed reading "
        "zip archive: failed finding central directory)"),
    "animate-ckpt-other-zip": Case(
        [*ANIMATE, "--checkpoint", "$other_pt"],
        "$other_pt: not a readable gnngarment checkpoint"),
    "animate-ckpt-missing-keys": Case(
        [*ANIMATE, "--checkpoint", "$nokeys_pt"],
        "$nokeys_pt: not a model checkpoint (no model_config or model_state)"),
    "animate-ckpt-other-architecture": Case(
        [*ANIMATE, "--checkpoint", "$otherarch_pt"],
        "$otherarch_pt: the weights do not fit"),
    "animate-ckpt-pickled-code": Case(
        [*ANIMATE, "--checkpoint", "$code_pt"],
        "$code_pt: not a readable gnngarment checkpoint"),
    "animate-fps-nan": Case(
        [*ANIMATE, "--fps", "nan"],
        "--fps must be a finite number > 0, got nan"),
    "animate-duration-negative": Case(
        [*ANIMATE, "--duration", "-1"],
        "--duration must be a finite number > 0, got -1.0"),
    "animate-motion-unknown": Case(
        [*ANIMATE, "--motion", "moonwalk"],
        "--motion moonwalk"),
    "animate-bvh-cut-short": Case(
        [*ANIMATE, "--motion", "$short_bvh"],
        "--motion $short_bvh: $short_bvh: not a readable BVH file"),
    "animate-npz-wrong-shape": Case(
        [*ANIMATE, "--motion", "$wrong_npz"],
        "$wrong_npz: 'poses' must be (T, 72|156|165), got (4, 70)"),
    "animate-mat-poses-string": Case(
        [*ANIMATE, "--motion", "$poses_string_mat"],
        "$poses_string_mat: poses is a string ('abc'), expected numbers"),
    "animate-mat-poses-struct": Case(
        [*ANIMATE, "--motion", "$poses_struct_mat"],
        "$poses_struct_mat: poses is a struct, expected numbers"),
    "animate-mat-trans-cell": Case(
        [*ANIMATE, "--motion", "$trans_cell_mat"],
        "$trans_cell_mat: trans is a cell array, expected numbers"),
    "animate-mat-poses-nan": Case(
        [*ANIMATE, "--motion", "$poses_nan_mat"],
        "$poses_nan_mat: poses contains NaN or inf"),
    "animate-joint-map-unknown": Case(
        [*ANIMATE, "--motion", "$clip_bvh", "--joint-map", "$map_json"],
        "$map_json: joint map key 'L_hipp' is not a canonical"),
    "animate-motion-up-axis": Case(
        [*ANIMATE, "--motion", "$clip_bvh", "--motion-up-axis", "w"],
        "--motion-up-axis must be auto, y or z, got 'w'"),
    "animate-shape-unknown": Case(
        [*ANIMATE, "--body-shape", "giant"],
        "--body-shape giant"),
    "animate-shape-unknown-key": Case(
        [*ANIMATE, "--body-shape", "$shape_key_json"],
        "$shape_key_json: unknown Anny phenotype(s) ['heigth']"),
    "animate-shape-not-mapping": Case(
        [*ANIMATE, "--body-shape", "$shape_list_json"],
        "$shape_list_json: expected a mapping"),
    "animate-shape-out-of-range": Case(
        [*ANIMATE, "--body-shape", "$shape_range_yaml"],
        "$shape_range_yaml: Anny phenotype 'height' must be in [0, 1], got 2.0"),
    "animate-format": Case(
        [*ANIMATE, "--format", "obj,xyz"],
        "--format: unknown ['xyz']; choose from obj, pc2, glb, gif"),
    "animate-out-is-file": Case(
        [*ANIMATE[:3], "$out/notes.txt", *ANIMATE[4:]],
        "--out $out/notes.txt: $out/notes.txt is a file, not a folder"),
    "animate-out-proc": Case(
        [*ANIMATE[:3], "/proc/gnngarment", *ANIMATE[4:]],
        "--out /proc/gnngarment: cannot write in /proc"),
    "animate-up-axis": Case(
        [*ANIMATE, "--up-axis", "w"],
        "--up-axis must be z, y or auto, got 'w'"),
    "animate-fix-units": Case(
        [*ANIMATE, "--fix-units", "furlong"],
        "--fix-units must be auto, m, cm, mm, got 'furlong'"),
    "animate-scale-zero": Case(
        [*ANIMATE, "--scale", "0"],
        "--scale must be a finite number > 0, got 0.0"),
    "animate-scale-negative": Case(
        [*ANIMATE, "--scale", "-1"],
        "--scale must be a finite number > 0, got -1.0"),
    "animate-scale-nan": Case(
        [*ANIMATE, "--scale", "nan"],
        "--scale must be a finite number > 0, got nan"),
    "animate-offset-nan": Case(
        [*ANIMATE, "--offset", "0", "nan", "0"],
        "--offset must be 3 finite numbers (metres), got [0.0, nan, 0.0]"),
    "animate-influences": Case(
        [*ANIMATE, "--influences", "0"],
        "--influences must be in 1..8, got 0"),
    "animate-source-body-and-scale": Case(
        [*ANIMATE, "--source-body", "$far", "--scale", "2"],
        "$far: with --source-body the fit finds units, up axis and position itself; leave out "
        "--scale"),
    "animate-off-body": Case(
        ["animate", "$far", "--out", "$new", "--duration", "0.2"],
        "$far: the garment is not on the rest body"),
    # ---- body --------------------------------------------------------------------------------
    "body-fps-zero": Case(
        [*BODY, "--fps", "0"],
        "--fps must be a finite number > 0, got 0.0"),
    "body-fps-nan": Case(
        [*BODY, "--fps", "nan"],
        "--fps must be a finite number > 0, got nan"),
    "body-duration-negative": Case(
        [*BODY, "--duration", "-1"],
        "--duration must be a finite number > 0, got -1.0"),
    "body-shape-unknown": Case(
        [*BODY, "--shape", "giant"],
        "--shape giant: unknown Anny shape 'giant'"),
    "body-model-unknown": Case(
        [*BODY, "--model", "mannequin"],
        "--model must be 'anny' or 'smpl', got 'mannequin'"),
    "body-smpl-missing": Case(
        [*BODY, "--model", "smpl", "--smpl-path", "$work/SMPL.npz"],
        "$work/SMPL.npz: SMPL model file not found"),
    "body-smpl-pickled-code": Case(
        [*BODY, "--model", "smpl", "--smpl-path", "$smpl_code_npz"],
        "$smpl_code_npz: holds pickled Python objects, which are refused"),
    "body-bvh-cut-short": Case(
        [*BODY, "--motion", "$short_bvh"],
        "$short_bvh: not a readable BVH file"),
    "body-joint-map-unknown": Case(
        [*BODY, "--motion", "$clip_bvh", "--joint-map", "$map_json"],
        "$map_json: joint map key 'L_hipp' is not a canonical"),
    "body-motion-up-axis": Case(
        [*BODY, "--motion", "$clip_bvh", "--motion-up-axis", "w"],
        "--motion-up-axis must be auto, y or z, got 'w'"),
    "body-out-is-file": Case(
        ["body", "--out", "$out/notes.txt", "--duration", "0.2"],
        "$out/notes.txt: cannot create the output folder"),
    # ---- attribute ---------------------------------------------------------------------------
    "attribute-target": Case(
        [*ATTRIBUTE, "--target", "face"],
        "--target must be one of"),
    "attribute-n-steps": Case(
        [*ATTRIBUTE, "--n-steps", "0"],
        "--n-steps must be in 1..1000"),
    "attribute-off-body": Case(
        ["attribute", "$shipped", "$far", "--out", "$new", "--n-steps", "2", "--duration", "0.2"],
        "$far: the garment is not on the rest body"),
    "attribute-ckpt-missing-keys": Case(
        ["attribute", "$nokeys_pt", "$skirt", "--out", "$out"],
        "$nokeys_pt: not a model checkpoint (no model_config or model_state)"),
    "attribute-fps-nan": Case(
        [*ATTRIBUTE, "--fps", "nan"],
        "--fps must be a finite number > 0, got nan"),
    "attribute-heat": Case(
        [*ATTRIBUTE, "--heat", "tangent"],
        "--heat must be one of normal, all, got 'tangent'"),
    "attribute-scale": Case(
        [*ATTRIBUTE, "--scale", "cubic"],
        "--scale must be one of linear, log, got 'cubic'"),
    "attribute-frame": Case(
        [*ATTRIBUTE, "--frame", "9999"],
        "--frame: frame index 9999 is out of range for a motion of 7 frames"),
    "attribute-vertex": Case(
        [*ATTRIBUTE, "--vertex", "99999"],
        "--vertex: target vertex 99999 is out of range for a garment of 300 vertices"),
    "attribute-body-model": Case(
        [*ATTRIBUTE, "--body-model", "smplx"],
        "--body-model must be 'anny' or 'smpl', got 'smplx'"),
    "attribute-smpl-pickled-code": Case(
        [*ATTRIBUTE, "--body-model", "smpl", "--smpl-path", "$smpl_code_npz"],
        "$smpl_code_npz: holds pickled Python objects, which are refused"),
    "attribute-motion-up-axis": Case(
        [*ATTRIBUTE, "--motion-up-axis", "x"],
        "--motion-up-axis must be auto, y or z, got 'x'"),
    "attribute-out-is-file": Case(
        [*ATTRIBUTE[:4], "$out/notes.txt", *ATTRIBUTE[5:]],
        "--out $out/notes.txt: $out/notes.txt is a file, not a folder"),
    # ---- train -------------------------------------------------------------------------------
    "train-top-level-list": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/t.yaml: expected a mapping at the top level",
        {"t.yaml": "- epochs: 1\n"}),
    "train-unknown-key": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/t.yaml: key 'epochz'",
        {"t.yaml": TRAIN + "epochz: 3\n"}),
    "train-pairs-per-batch": Case(
        ["train", "--config", "$work/t.yaml", "--set", "pairs_per_batch=0"],
        "(with --set pairs_per_batch=0): key 'pairs_per_batch': must be >= 1, got 0",
        {"t.yaml": TRAIN}),
    "train-learning-rate-nan": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/t.yaml: key 'learning_rate': must be a finite number > 0, got nan",
        {"t.yaml": TRAIN + "learning_rate: .nan\n"}),
    "train-epochs-zero": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/t.yaml: key 'epochs': must be >= 1, got 0",
        {"t.yaml": TRAIN.replace("epochs: 1", "epochs: 0")}),
    "train-data-missing": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/nodata/manifest.json: no prepared cache here",
        {"t.yaml": TRAIN.replace("$cache", "$work/nodata")}),
    "train-resume-nothing": Case(
        ["train", "--config", "$work/t.yaml", "--resume"],
        "--resume: $out/last.pt: checkpoint not found",
        {"t.yaml": TRAIN}),
    "train-config-missing": Case(
        ["train", "--config", "$work/none.yaml"],
        "$work/none.yaml: config file not found"),
    "train-model-config-missing": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/m.yaml: config file not found",
        {"t.yaml": TRAIN + "model_config: $work/m.yaml\n"}),
    "train-set-syntax": Case(
        ["train", "--config", "$work/t.yaml", "--set", "epochs"],
        "(with --set epochs): key 'epochs'",
        {"t.yaml": TRAIN}),
    "train-set-too-large": Case(
        ["train", "--config", "$work/t.yaml", "--set", "pairs_per_batch=1000000000"],
        "key 'pairs_per_batch': must be <= 256, got 1,000,000,000",
        {"t.yaml": TRAIN}),
    # YAML that is valid to a lax parser but not a config (issue 38): one line each.
    "train-yaml-duplicate-key": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/t.yaml: not a valid YAML file: duplicate key 'epochs' (line",
        {"t.yaml": TRAIN + "epochs: 2\n"}),
    "train-yaml-alias-bomb": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/t.yaml: YAML expands to more than 100,000 values",
        {"t.yaml": ALIAS_BOMB}),
    "train-yaml-python-tag": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/t.yaml: not a valid YAML file: a tag that would build an object is not "
        "allowed",
        {"t.yaml": TRAIN + "seed: !!python/object/apply:os.system [touch $work/ran]\n"}),
    "train-yaml-deep": Case(
        ["train", "--config", "$work/t.yaml"],
        "$work/t.yaml: YAML nested too deeply (at most 64 levels)",
        {"t.yaml": "a: " + "[" * 4000 + "]" * 4000 + "\n"}),
    "body-shape-yaml-duplicate-key": Case(
        [*BODY, "--shape", "$work/s.yaml"],
        "$work/s.yaml: not a valid YAML file: duplicate key 'height' (line 2, column 1)",
        {"s.yaml": "height: 0.5\nheight: 0.6\n"}),
    "body-shape-yaml-string": Case(
        [*BODY, "--shape", "$work/s.yaml"],
        "$work/s.yaml: expected a mapping of phenotype values",
        {"s.yaml": "just a string\n"}),
    "body-shape-json-duplicate-key": Case(
        [*BODY, "--shape", "$work/s.json"],
        "duplicate key(s) ['height']",
        {"s.json": '{"height": 0.5, "height": 0.6}'}),
    # ---- evaluate ----------------------------------------------------------------------------
    "evaluate-json-folder": Case(
        [*EVALUATE, "--json", "$out"],
        "--json $out: is a folder"),
    "evaluate-cache-missing": Case(
        ["evaluate", "--checkpoint", "$tiny", "--data", "$work/none", "--json", "$out/r.json"],
        "$work/none/manifest.json: no prepared cache here"),
    "evaluate-split": Case(
        [*EVALUATE, "--split", "nosuch", "--json", "$out/r.json"],
        "$cache/manifest.json: no split 'nosuch' (has ['test', 'train', 'val'])"),
    "evaluate-ckpt-missing-keys": Case(
        [*EVALUATE[:2], "$nokeys_pt", *EVALUATE[3:]],
        "$nokeys_pt: not a model checkpoint"),
    "evaluate-ckpt-truncated": Case(
        ["evaluate", "--checkpoint", "$truncated_pt", "--json", "$out/r.json"],
        "$truncated_pt: not a readable gnngarment checkpoint"),
    # ---- prepare (a hidden *.tmp file of the user's in --output stays) -----------------------
    "prepare-fps": Case(
        ["prepare", "--config", "$work/d.yaml"],
        "$work/d.yaml: key 'fps': must be a finite number > 0, got -30.0",
        {"d.yaml": data_config(fps="-30")}),
    "prepare-motion": Case(
        ["prepare", "--config", "$work/d.yaml"],
        "$work/d.yaml: key 'motions': unknown ['moonwalk']",
        {"d.yaml": data_config(motions="[walk, moonwalk]")}),
    "prepare-garment-type": Case(
        ["prepare", "--config", "$work/d.yaml"],
        "$work/d.yaml: key 'garment_types': unknown ['cape']",
        {"d.yaml": data_config(garment_types="[skirt, cape]")}),
    "prepare-garment-vertices": Case(
        ["prepare", "--config", "$work/d.yaml"],
        "$work/d.yaml: key 'garment_vertices': expected [low, high] with 300 <= low <= high, got "
        "[420, 300]",
        {"d.yaml": data_config(garment_vertices="[420, 300]")}),
    "prepare-motion-variants": Case(
        ["prepare", "--config", "$work/d.yaml"],
        "$work/d.yaml: key 'motion_variants': 3 variants need at least as many motions per pair",
        {"d.yaml": data_config() + "motion_variants: 3\n"}),
    "prepare-simulation-missing": Case(
        ["prepare", "--config", "$work/d.yaml"],
        "$work/d.yaml: $work/nosim.yaml: config file not found",
        {"d.yaml": data_config(simulation="$work/nosim.yaml")}),
    "prepare-workers": Case(
        ["prepare", "--config", "$work/d.yaml", "--workers", "-1"],
        "--workers must be >= 0 (0: one per core), got -1",
        {"d.yaml": data_config()}),
    "prepare-executor": Case(
        ["prepare", "--config", "$work/d.yaml", "--executor", "slurm"],
        "--executor/--address: key 'executor': unknown 'slurm'",
        {"d.yaml": data_config()}),
    "prepare-splits": Case(
        ["prepare", "--config", "$work/d.yaml"],
        "$work/d.yaml: 4 items cannot hold 2 validation + 2 test ones",
        {"d.yaml": data_config() + "splits: {val_garments: 2, test_garments: 2}\n"}),
    "prepare-motions-repeat": Case(
        ["prepare", "--config", "$work/d.yaml"],
        "$work/d.yaml: key 'motions_per_pair'",
        {"d.yaml": data_config(motions_per_pair="3")}),
    "prepare-cloth3d-missing": Case(
        ["prepare", "--from-cloth3d", "$work/cloth3d", "--smpl-model", "$smpl_code_npz",
         "--output", "$out"],
        "$work/cloth3d: CLOTH3D folder not found"),
    # ---- benchmark-accuracy ------------------------------------------------------------------
    "benchmark-cache-missing": Case(
        ["benchmark-accuracy", "--config", "$work/t.yaml", "--output", "$out/results.md"],
        "$work/nodata/manifest.json: no prepared cache here",
        {"t.yaml": TRAIN.replace("$cache", "$work/nodata")}),
    "benchmark-config-list": Case(
        ["benchmark-accuracy", "--config", "$work/t.yaml", "--output", "$out/results.md"],
        "$work/t.yaml: expected a mapping at the top level",
        {"t.yaml": "[1, 2]\n"}),
    "benchmark-variant": Case(
        ["benchmark-accuracy", "--config", "$work/t.yaml", "--variant", "nosuch", "--output",
         "$out/results.md"],
        "unknown variant(s) ['nosuch']",
        {"t.yaml": TRAIN}),
    "benchmark-output-folder": Case(
        ["benchmark-accuracy", "--config", "$work/t.yaml", "--output", "$out"],
        "--output $out: is a folder; give a file name",
        {"t.yaml": TRAIN}),
    # ---- motions (it takes no options: click's usage error) ----------------------------------
    "motions-extra-argument": Case(
        ["motions", "walk"],
        "unexpected extra argument"),
    "motions-unknown-option": Case(
        ["motions", "--fast"],
        "No such option: --fast"),
}

#: Cases whose error is click's usage message (a framed panel, not our ``error:`` line).
USAGE = {"motions-extra-argument", "motions-unknown-option"}


def snapshot(folder: Path) -> dict[str, tuple[int, int] | None]:
    """Every file (size, mtime) and folder (None) under ``folder``, by relative path."""
    return {str(path.relative_to(folder)): (None if path.is_dir() else
                                            (path.stat().st_size, path.stat().st_mtime_ns))
            for path in sorted(folder.rglob("*"))}


@pytest.mark.parametrize("name", list(CASES))
def test_hostile_input_is_refused_in_one_line(name: str, inputs: dict[str, Path],
                                              tmp_path: Path) -> None:
    case = CASES[name]
    work = tmp_path / "work"
    out = work / "out"
    out.mkdir(parents=True)
    for file_name, text in USER_FILES.items():
        (out / file_name).write_text(text)
    names = {key: str(value) for key, value in inputs.items()}
    names |= {"work": str(work), "out": str(out), "new": str(work / "new")}
    for file_name, text in (case.write or {}).items():
        (work / file_name).write_text(Template(text).substitute(names))
    args = [Template(arg).substitute(names) for arg in case.args]
    expect = Template(case.expect).substitute(names)
    before = snapshot(work), snapshot(inputs["inputs"])

    result = runner.invoke(app, args)

    text = " ".join(result.output.split())  # rich may wrap
    assert result.exit_code == 2, (args, result.output)
    assert "Traceback" not in result.output, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    assert expect in text, (expect, result.output)
    if name not in USAGE:
        # Our error is the last thing printed, on one line of its own.
        lines = [line for line in result.stderr.splitlines() if line.strip()]
        assert lines and lines[-1].startswith("error: "), result.output
        assert expect in lines[-1], (expect, lines[-1])
    assert (snapshot(work), snapshot(inputs["inputs"])) == before
    for file_name, content in USER_FILES.items():
        assert (out / file_name).read_text() == content
    assert not inputs["marker"].exists(), "a pickle in an input file ran code"


@pytest.mark.parametrize("args, expect", [
    (["animate", "absent.obj", "--fps", "1e9"], "--fps must be at most 240"),
    (["animate", "absent.obj", "--duration", "1e6"], "--duration must be at most 600"),
    (["animate", "absent.obj", "--fps", "1e-6"], "fewer than 2 frames"),
    (["animate", "absent.obj", "--duration", "1e-9"], "fewer than 2 frames"),
    (["body", "--out", "never", "--duration", "1e5"], "--duration must be at most 600"),
    (["attribute", "absent.pt", "absent.obj", "--out", "never", "--n-steps", "1000000000"],
     "--n-steps must be in 1..1000"),
])
def test_numbers_that_ask_for_absurd_work_are_refused_first(args, expect, tmp_path,
                                                            monkeypatch) -> None:
    """Issue 38: these ended in MemoryError tracebacks (one after 9.8 GB) or exported a
    single frame; each is refused by the option's name before anything is read."""
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert expect in " ".join(result.output.split()), result.output
    assert not (tmp_path / "never").exists()


def test_an_animation_larger_than_the_free_memory_is_refused_before_the_work(
        inputs, tmp_path, monkeypatch) -> None:
    """Issue 38: frames x vertices within each option's limit can still exceed the
    machine (600 s at 240 fps of a 5,000-vertex dress: ~545 GB); refused by the options
    that set the frame count, before the drape or the inference, with no output folder."""
    from gnngarment.inference import animation_memory

    monkeypatch.setattr(animation_memory, "available_bytes", lambda: 50e6)  # 50 MB free
    out = tmp_path / "never"
    result = runner.invoke(app, ["animate", str(inputs["skirt"]), "--out", str(out),
                                 "--duration", "2"])
    text = " ".join(result.output.split())
    assert result.exit_code == 2, result.output
    assert "more than this machine has free (0.1 GB available)" in text, text
    assert "--duration" in text and "--fps" in text
    assert not out.exists()
