"""``gnngarment prepare --from-cloth3d DIR --smpl-model FILE|FOLDER`` (or
``--smpl-model-female F --smpl-model-male M``): the prepared cache from real CLOTH3D
sequences (every garment of every sequence becomes one cache sequence).

Frames (measured on real data, :mod:`data_prep.cloth3d.frames`): the rest OBJ is
canonical (root at the origin, no ``trans``, no ``zrot``) and is used as stored, moved
onto our rest body's pelvis ``J_0``; a ``.pc16`` frame lies in the frame of
``SMPL(pose, shape, trans=0) − J_0``, and our SMPL body puts the pelvis at
``J_0 + (trans_t − trans_0)``, so garment frames are moved by the same amount.

Each sequence is posed with the SMPL model of its ``info.mat`` gender (0 female,
1 male). Everything that can fail on the inputs fails before any work, in one line: a
given model file that is missing or unreadable, and a gender some sequence needs whose
model was not given.

Every garment is checked before it is written, and left out (reported in
``build_report.json``) instead of producing misaligned data:

- **frames vs body** — the garment must sit on the posed body (median distance to the
  body ≤ ``alignment_tolerance``) in :data:`CHECKED_FRAMES` frames spread over the
  sequence, not just the first;
- **rest template vs frames** — with each frame's root rotation undone, the frames must
  lie over the rest template (no z-turn beyond 20°, median distance ≤ 15 cm;
  :mod:`data_prep.cloth3d.rest_alignment`): this is what catches a turned template,
  which the body check cannot see (the frames are right, the template is not).
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from gnngarment.io.atomic import atomic_write_bytes

#: A garment vertex is "on the body" within this median distance (metres).
ALIGNMENT_TOLERANCE = 0.10
#: Frames (first, last and evenly between) in which the garment must sit on the body.
CHECKED_FRAMES = 5
#: CLOTH3D's split folders, mapped to our split names.
SPLIT_FOLDERS = {"train": "train", "validation": "val", "val": "val", "test": "test"}
#: File names looked for in an SMPL folder, in order: smplx's, the official SMPL for
#: Python download (v1.1.0, v1.0.0) and the CLOTH3D starter kit's.
SMPL_FILE_NAMES = {
    gender: (f"SMPL_{gender.upper()}.pkl", f"SMPL_{gender.upper()}.npz",
             f"basicmodel_{gender[0]}_lbs_10_207_0_v1.1.0.pkl",
             f"basicModel_{gender[0]}_lbs_10_207_0_v1.0.0.pkl", f"model_{gender[0]}.pkl")
    for gender in ("female", "male")
}


def _split_folders(root: Path) -> dict[str, Path]:
    found = {split: root / folder for folder, split in SPLIT_FOLDERS.items()
             if (root / folder).is_dir()}
    return found or {"train": root}


def smpl_model_files(smpl_model: str | Path | None = None,
                     smpl_model_female: str | Path | None = None,
                     smpl_model_male: str | Path | None = None) -> dict[str, Path | None]:
    """The SMPL model file for each gender, or ``None`` where there is none.

    A per-gender argument wins over ``smpl_model``. Each argument is a model file (used
    as is) or a folder searched for :data:`SMPL_FILE_NAMES`; ``smpl_model`` as a single
    file serves both genders.

    Returns:
        ``{"female": Path | None, "male": Path | None}``; ``None`` only where no argument
        applies or a shared ``smpl_model`` folder holds no file for that gender.

    Raises:
        FileNotFoundError: a given path that does not exist, or a per-gender folder with
            no model for its gender (one line naming it).
    """
    from gnngarment.body.smpl_model import SMPL_DOWNLOAD_HINT, SMPLModelError

    given = {"female": smpl_model_female, "male": smpl_model_male}
    files: dict[str, Path | None] = {}
    for gender, own in given.items():
        path = own if own is not None else smpl_model
        if path is None or not str(path):
            files[gender] = None
            continue
        path = Path(path).expanduser()
        if not path.exists():
            raise SMPLModelError(f"{path}: SMPL model file not found; {SMPL_DOWNLOAD_HINT}")
        if path.is_dir():
            found = [path / name for name in SMPL_FILE_NAMES[gender] if (path / name).is_file()]
            if not found and own is not None:
                raise SMPLModelError(f"{path}: no {gender} SMPL model here (looked for "
                                     f"{', '.join(SMPL_FILE_NAMES[gender])})")
            files[gender] = found[0] if found else None
        else:
            files[gender] = path
    return files


def _missing_model_message(gender: str, info_file: Path, count: int,
                           smpl_model: str | Path | None) -> str:
    where = (f"{smpl_model} holds none of {', '.join(SMPL_FILE_NAMES[gender])}"
             if smpl_model is not None else f"no --smpl-model-{gender} given")
    return (f"{info_file}: gender = {('female', 'male').index(gender)} ({gender}) but there "
            f"is no {gender} SMPL model ({where}; {count} sequence(s) need it): pass "
            f"--smpl-model-{gender} FILE, or --smpl-model FOLDER holding "
            f"SMPL_{gender.upper()}.pkl")


def _worst_body_distance(positions: np.ndarray, body_points: np.ndarray
                         ) -> tuple[float, int]:
    """Largest median garment-to-body distance over :data:`CHECKED_FRAMES` frames.

    Shapes:
        positions ``(T, N, 3)``, body_points ``(T, S, 3)`` metres → (metres, frame).
    """
    from scipy.spatial import cKDTree

    frames = np.unique(np.linspace(0, len(positions) - 1, CHECKED_FRAMES).round().astype(int))
    medians = [float(np.median(cKDTree(body_points[t]).query(positions[t])[0]))
               for t in frames]
    worst = int(np.argmax(medians))
    return medians[worst], int(frames[worst])


def build_from_cloth3d(root: str | Path, smpl_model: str | Path | None, output: str | Path,
                       fps: float = 30.0, levels: int = 3, landmarks: int = 64,
                       body_vertices: int = 512, collision_points: int = 4096,
                       alignment_tolerance: float = ALIGNMENT_TOLERANCE,
                       smpl_model_female: str | Path | None = None,
                       smpl_model_male: str | Path | None = None) -> dict[str, Any]:
    """Convert a CLOTH3D download (``train/``, ``val``/``validation/``, ``test/`` of
    sequence folders, or one folder of sequences) into a prepared cache.

    Args:
        root: the download (or one folder of sequence folders).
        smpl_model: SMPL model file for both genders, or a folder holding one per gender
            (:data:`SMPL_FILE_NAMES`); may be ``None`` when both per-gender files are
            given or every sequence has one gender.
        output: the cache folder; nothing is written there before the inputs are checked.
        smpl_model_female / smpl_model_male: model file (or folder) for ``gender`` 0 / 1
            sequences; each wins over ``smpl_model``.

    Returns:
        The build report (also written as ``build_report.json``): ``splits`` counts,
        ``skipped`` (sequence or garment → one-line reason), ``seconds``.

    Raises:
        ValueError: missing folder, no SMPL model at all, or none for a gender some
            sequence needs (names that sequence's ``info.mat``).
        FileNotFoundError: a given SMPL model file that is missing or unreadable
            (``SMPLModelError``, naming the file).
    """
    from tqdm import tqdm

    from data_prep.cloth3d import Cloth3DError, read_info, read_sequence, scan_dataset
    from gnngarment.body.cloth3d_motion import load_cloth3d_motion
    from gnngarment.body.joint_reach import joint_region_distances
    from gnngarment.body.smpl_model import SMPL_DOWNLOAD_HINT, SMPLBodyModel
    from gnngarment.body.weight_transfer import transfer_body_weights
    from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
    from gnngarment.data.cache import (
        BodyRecord,
        GarmentRecord,
        SequenceRecord,
        topology_key,
        write_body,
        write_garment,
        write_manifest,
        write_sequence,
        write_topology,
    )
    from gnngarment.geometry.normals import vertex_normals
    from gnngarment.geometry.prepare import GarmentPreparationConfig, prepare_garment

    root, output = Path(root), Path(output)
    if not root.is_dir():
        raise ValueError(f"{root}: CLOTH3D folder not found")
    started = time.perf_counter()
    files = smpl_model_files(smpl_model, smpl_model_female, smpl_model_male)
    if all(path is None for path in files.values()):
        where = f"{smpl_model} holds no SMPL model file; " if smpl_model is not None else ""
        raise ValueError(f"{where}CLOTH3D needs an SMPL model (--smpl-model FILE|FOLDER or "
                         f"--smpl-model-female/--smpl-model-male FILE): {SMPL_DOWNLOAD_HINT}")

    # Before any work: every sequence's gender has a model, and every model loads.
    skipped: dict[str, str] = {}
    todo: list[tuple[str, Path, str]] = []  # (split, folder, gender)
    needed: dict[str, list[Path]] = {"female": [], "male": []}
    for split, folder in _split_folders(root).items():
        good, bad = scan_dataset(folder)
        for path, message in bad:
            skipped[str(path)] = message
        for path in good:
            gender = read_info(path / "info.mat")["gender"]
            if gender not in (0, 1):
                skipped[str(path)] = (f"{path / 'info.mat'}: gender = {gender}, expected 0 "
                                      f"(female) or 1 (male)")
                continue
            name = ("female", "male")[gender]
            needed[name].append(path)
            todo.append((split, path, name))
    for gender, paths in needed.items():
        if paths and files[gender] is None:
            raise ValueError(_missing_model_message(gender, paths[0] / "info.mat", len(paths),
                                                    smpl_model))
    loaded: dict[Path, SMPLBodyModel] = {}
    body_models: dict[str, SMPLBodyModel] = {}
    for gender, path in files.items():
        if path is not None:
            if path not in loaded:
                loaded[path] = SMPLBodyModel(path, gender=gender)
            body_models[gender] = loaded[path]

    splits: dict[str, list[str]] = {"train": [], "val": [], "test": []}
    sequences: dict[str, dict] = {}
    for split, path, gender in tqdm(todo, desc="CLOTH3D", unit="sequence"):
        try:
            sequence = read_sequence(path, fps=fps)
        except Cloth3DError as error:
            skipped[str(path)] = str(error)
            continue
        body_model = body_models[gender]
        shape = np.asarray(sequence.shape, dtype=np.float32)
        body_name = f"{path.name}_body"
        body = body_shape_inputs(body_model, shape, body_vertices)
        motion = load_cloth3d_motion(path / "info.mat", fps=fps)
        frames = body_motion_inputs(body_model, shape, motion, body_vertices)
        samples = body_model.feature_vertex_indices(min(collision_points,
                                                        len(body.rest_vertices)))
        body_points = frames.vertices[:, samples]
        shift = body.joints[0] + (sequence.trans - sequence.trans[0])  # (T, 3)
        kept = []
        for garment_name, garment in sequence.garments.items():
            name = f"{path.name}_{garment_name}"
            positions = garment.frames + shift[:, None, :].astype(np.float32)
            distance, frame = _worst_body_distance(positions, body_points)
            if distance > alignment_tolerance:
                skipped[name] = (f"garment is {distance:.2f} m from the body in frame {frame}: "
                                 "CLOTH3D frame conventions do not hold here")
                continue
            problem = sequence.rest_alignment(garment_name).problem()
            if problem is not None:  # frames on the body, but the template is not theirs
                skipped[name] = f"{path / garment_name}.obj: {problem}"
                continue
            kept.append((name, garment_name, garment, positions))
        if not kept:
            continue
        write_body(output, BodyRecord(body_name, body.joints, body.distances, body.subset))
        normals = np.stack([vertex_normals(v, body.faces)[samples] for v in frames.vertices])
        for name, garment_name, garment, positions in kept:
            rest = garment.rest_pos + body.joints[0]
            prepared = prepare_garment(rest, garment.faces, GarmentPreparationConfig(
                levels=levels, landmarks=landmarks), source=str(path / garment_name))
            topology = topology_key(garment.faces)
            if not (output / "topologies" / f"{topology}.npz").is_file():
                write_topology(output, topology, prepared.hierarchy)
            skinning = body_model.skinning_weights()
            write_garment(output, GarmentRecord(
                name=name, rest_pos=rest, faces=garment.faces,
                descriptor=prepared.descriptor, topology=topology,
                garment_type=garment_name.lower(), body=body_name,
                body_weights=transfer_body_weights(rest, body.rest_vertices, skinning),
                joint_distances=joint_region_distances(rest, body.rest_vertices, skinning)))
            write_sequence(output, SequenceRecord(
                name=name, garment=name, body=body_name, motion=path.name, fps=fps,
                positions=positions, joint_transforms=frames.joint_transforms,
                motion_features=frames.motion_features, velocities=frames.velocities,
                body_points=body_points, body_normals=normals))
            splits[split].append(name)
            sequences[name] = {"garment": name, "body": body_name, "motion": path.name,
                               "frames": int(positions.shape[0]),
                               "garment_type": garment_name.lower()}
    manifest = write_manifest(output, splits, sequences, extra={"source": "cloth3d"})
    report = {"output": str(output), "seconds": time.perf_counter() - started,
              "splits": {k: len(v) for k, v in splits.items()}, "skipped": skipped,
              "smpl_models": {gender: str(path) if path is not None else None
                              for gender, path in files.items()},
              "manifest_hash": manifest["hash"]}
    atomic_write_bytes(output / "build_report.json", json.dumps(report, indent=2).encode())
    return report


__all__ = ["ALIGNMENT_TOLERANCE", "CHECKED_FRAMES", "SMPL_FILE_NAMES", "build_from_cloth3d",
           "smpl_model_files"]
