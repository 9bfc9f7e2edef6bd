"""``gnngarment prepare --from-cloth3d DIR --smpl-model FILE``: the prepared cache from
real CLOTH3D sequences (every garment of every sequence becomes one cache sequence).

Frames: a ``.pc16`` frame lies in the frame of ``SMPL(pose, shape, trans=0) − J_0``
(DESIGN.md). Our SMPL body puts the pelvis at ``J_0 + (trans_t − trans_0)``, so garment
frames are moved by the same amount. These conventions come from CLOTH3D's starter kit
and third-party readers and are unverified on real data here; every sequence is
therefore checked: if the garment does not sit on the posed body in its first frame
(median distance to the body above ``alignment_tolerance``), the sequence is reported
and left out instead of silently producing misaligned data.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from gnngarment.geometry.files import atomic_write_bytes

#: A garment vertex is "on the body" within this median distance (metres).
ALIGNMENT_TOLERANCE = 0.10
#: CLOTH3D's split folders, mapped to our split names.
SPLIT_FOLDERS = {"train": "train", "validation": "val", "val": "val", "test": "test"}


def _split_folders(root: Path) -> dict[str, Path]:
    found = {split: root / folder for folder, split in SPLIT_FOLDERS.items()
             if (root / folder).is_dir()}
    return found or {"train": root}


def build_from_cloth3d(root: str | Path, smpl_model: str | Path, output: str | Path,
                       fps: float = 30.0, levels: int = 3, landmarks: int = 64,
                       body_vertices: int = 512, collision_points: int = 4096,
                       alignment_tolerance: float = ALIGNMENT_TOLERANCE) -> dict[str, Any]:
    """Convert a CLOTH3D download (``train/``, ``val``/``validation/``, ``test/`` of
    sequence folders, or one folder of sequences) into a prepared cache.

    Raises:
        ValueError: missing folder or SMPL file (names it).
    """
    from tqdm import tqdm

    from data_prep.cloth3d import Cloth3DError, read_sequence, scan_dataset
    from gnngarment.body.motion_io import load_cloth3d_motion
    from gnngarment.body.smpl_model import SMPLBodyModel
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
    from gnngarment.evaluation.baselines import transfer_body_weights
    from gnngarment.geometry.normals import vertex_normals
    from gnngarment.geometry.prepare import GarmentPreparationConfig, prepare_garment

    root, output = Path(root), Path(output)
    if not root.is_dir():
        raise ValueError(f"{root}: CLOTH3D folder not found")
    started = time.perf_counter()
    body_models: dict[int, SMPLBodyModel] = {}
    splits: dict[str, list[str]] = {"train": [], "val": [], "test": []}
    sequences: dict[str, dict] = {}
    skipped: dict[str, str] = {}
    for split, folder in _split_folders(root).items():
        good, bad = scan_dataset(folder)
        for path, message in bad:
            skipped[str(path)] = message
        for path in tqdm(good, desc=f"CLOTH3D {split}", unit="sequence"):
            try:
                sequence = read_sequence(path, fps=fps)
            except Cloth3DError as error:
                skipped[str(path)] = str(error)
                continue
            gender = "female" if int(sequence.gender) == 0 else "male"
            key = 0 if gender == "female" else 1
            if key not in body_models:
                body_models[key] = SMPLBodyModel(smpl_model, gender=gender)
            body_model = body_models[key]
            shape = np.asarray(sequence.shape, dtype=np.float32)
            body_name = f"{path.name}_body"
            body = body_shape_inputs(body_model, shape, body_vertices)
            write_body(output, BodyRecord(body_name, body.joints, body.distances, body.subset))
            motion = load_cloth3d_motion(path / "info.mat", fps=fps)
            frames = body_motion_inputs(body_model, shape, motion, body_vertices)
            samples = body_model.feature_vertex_indices(min(collision_points,
                                                            len(body.rest_vertices)))
            normals = np.stack([vertex_normals(v, body.faces)[samples] for v in frames.vertices])
            shift = body.joints[0] + (sequence.trans - sequence.trans[0])  # (T, 3)
            for garment_name, garment in sequence.garments.items():
                name = f"{path.name}_{garment_name}"
                positions = garment.frames + shift[:, None, :].astype(np.float32)
                distance = np.linalg.norm(positions[0][:, None, :]
                                          - frames.vertices[0][samples][None], axis=-1).min(1)
                if np.median(distance) > alignment_tolerance:
                    skipped[name] = (f"garment is {np.median(distance):.2f} m from the body in "
                                     "frame 0: CLOTH3D frame conventions do not hold here")
                    continue
                rest = garment.rest_pos + body.joints[0]
                prepared = prepare_garment(rest, garment.faces, GarmentPreparationConfig(
                    levels=levels, landmarks=landmarks), source=str(path / garment_name))
                topology = topology_key(garment.faces)
                if not (output / "topologies" / f"{topology}.npz").is_file():
                    write_topology(output, topology, prepared.hierarchy)
                weights = transfer_body_weights(rest, body.rest_vertices,
                                                body_model.skinning_weights())
                write_garment(output, GarmentRecord(
                    name=name, rest_pos=rest, faces=garment.faces,
                    descriptor=prepared.descriptor, topology=topology,
                    garment_type=garment_name.lower(), body=body_name, body_weights=weights))
                write_sequence(output, SequenceRecord(
                    name=name, garment=name, body=body_name, motion=path.name, fps=fps,
                    positions=positions, joint_transforms=frames.joint_transforms,
                    motion_features=frames.motion_features, velocities=frames.velocities,
                    body_points=frames.vertices[:, samples], body_normals=normals))
                splits[split].append(name)
                sequences[name] = {"garment": name, "body": body_name, "motion": path.name,
                                   "frames": int(positions.shape[0]),
                                   "garment_type": garment_name.lower()}
    manifest = write_manifest(output, splits, sequences, extra={"source": "cloth3d"})
    report = {"output": str(output), "seconds": time.perf_counter() - started,
              "splits": {k: len(v) for k, v in splits.items()}, "skipped": skipped,
              "manifest_hash": manifest["hash"]}
    atomic_write_bytes(output / "build_report.json", json.dumps(report, indent=2).encode())
    return report
