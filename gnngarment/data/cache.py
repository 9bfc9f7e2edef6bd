"""The prepared cache: what training, evaluation and the demo read.

Layout under a cache root (every file written atomically; ``manifest.json`` last)::

    manifest.json                 format version, code version, splits, sha256 and size of files
    topologies/<topology>.npz     pooling hierarchy (one per garment topology)
    garments/<garment>.npz        a garment on its rest body: rest_pos, faces, descriptor
    bodies/<body>.npz             rest joints, body-shape feature D, subset indices
    sequences/<sequence>.npz      one simulated (garment, body, motion) sequence
    outfits/<outfit>.npz          a layered outfit (garments worn together) simulated in one scene

A *garment* here is one garment design fitted to one body (same topology for every
body, different rest positions), as in CLOTH3D where every sequence has its own fit.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np

from gnngarment.geometry.hierarchy import PoolHierarchy
from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.io.npz import load_npz, save_npz_atomic

#: Bumped when the layout of any cache file changes: older caches are rebuilt.
#: 3: garments carry ``joint_distances`` (the weight reach is measured on the body).
CACHE_FORMAT_VERSION = 3

GARMENT_ARRAYS = ("rest_pos", "faces", "descriptor", "topology", "garment_type", "body")
BODY_ARRAYS = ("joints", "distances", "subset")
SEQUENCE_ARRAYS = ("garment", "body", "motion", "fps", "positions", "joint_transforms",
                   "motion_features", "velocities", "body_points", "body_normals")
OUTFIT_ARRAYS = ("sequence", "garments", "start_pos", "positions", "counts")


class CacheError(ValueError):
    """A prepared cache is missing, stale, truncated or inconsistent (names the file)."""


def file_hash(path: str | Path) -> str:
    """sha256 of a file's bytes (hex)."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def topology_key(faces: np.ndarray) -> str:
    """Name of a topology: a hash of its triangles (same faces ⇒ same hierarchy)."""
    faces = np.ascontiguousarray(np.asarray(faces, dtype=np.int64))
    return hashlib.sha256(faces.tobytes()).hexdigest()[:16]


@dataclass
class GarmentRecord:
    """``garments/<name>.npz``. Shapes: rest_pos ``(N, 3)`` metres: the template, the
    garment as worn (draped) on the rest body of ``body`` in the rest pose, where every
    sequence starts; faces ``(F, 3)``, descriptor ``(N*,)``; optional body_weights
    ``(N, 24)``, the body's skinning weights transferred from the nearest body vertices
    (the body-skinning baseline and prior); optional joint_distances ``(N, 24)`` metres,
    how far each joint's body region lies beyond the nearest body point
    (:func:`~gnngarment.body.joint_reach.joint_region_distances`: the weight reach);
    optional design_pos ``(N, 3)``, the undraped design the template was draped from
    (provenance only: no reader learns from it)."""

    name: str
    rest_pos: np.ndarray
    faces: np.ndarray
    descriptor: np.ndarray
    topology: str
    garment_type: str
    body: str
    body_weights: np.ndarray | None = None
    joint_distances: np.ndarray | None = None
    design_pos: np.ndarray | None = None


@dataclass
class BodyRecord:
    """``bodies/<name>.npz``. Shapes: joints ``(24, 3)`` rest joints (metres),
    distances ``(N_b', 24)`` the feature D, subset ``(N_b',)`` template indices."""

    name: str
    joints: np.ndarray
    distances: np.ndarray
    subset: np.ndarray


@dataclass
class SequenceRecord:
    """``sequences/<name>.npz``: one simulated sequence of ``T`` frames.

    Shapes:
        positions ``(T, N, 3)`` ground-truth garment vertices (world, metres);
        joint_transforms ``(T, 24, 4, 4)`` skinning transforms;
        motion_features ``(T, 75)`` joint axis-angles + root displacement;
        velocities ``(T, N_b', 3)`` body-subset velocities (m/s);
        body_points / body_normals ``(T, M, 3)`` posed-body collision samples with
        outward unit normals.
    """

    name: str
    garment: str
    body: str
    motion: str
    fps: float
    positions: np.ndarray
    joint_transforms: np.ndarray
    motion_features: np.ndarray
    velocities: np.ndarray
    body_points: np.ndarray
    body_normals: np.ndarray

    @property
    def num_frames(self) -> int:
        return int(self.positions.shape[0])


@dataclass
class OutfitRecord:
    """``outfits/<name>.npz``: garments worn together, simulated in one scene on the body
    and motion of ``sequence`` (a sequence of the cache: its joint transforms, motion
    features and velocities are the outfit's).

    Shapes:
        garments: ``G`` cache garment names, innermost first;
        start_pos: per garment ``(N_g, 3)`` where the simulation started [m]: the
            garment's template, moved out of the garments beneath it (they were draped
            apart);
        positions: per garment ``(T, N_g, 3)`` ground truth [m].
    """

    name: str
    sequence: str
    garments: list[str]
    start_pos: list[np.ndarray]
    positions: list[np.ndarray]


def _strings(record, names) -> dict[str, np.ndarray]:
    return {name: np.array(getattr(record, name)) for name in names}


def write_garment(root: Path, record: GarmentRecord) -> Path:
    path = root / "garments" / f"{record.name}.npz"
    save_npz_atomic(path, {
        "rest_pos": record.rest_pos.astype(np.float32), "faces": record.faces.astype(np.int64),
        "descriptor": record.descriptor.astype(np.float64),
        **({} if record.body_weights is None
           else {"body_weights": record.body_weights.astype(np.float32)}),
        **({} if record.joint_distances is None
           else {"joint_distances": record.joint_distances.astype(np.float32)}),
        **({} if record.design_pos is None
           else {"design_pos": record.design_pos.astype(np.float32)}),
        **_strings(record, ("topology", "garment_type", "body"))})
    return path


def write_body(root: Path, record: BodyRecord) -> Path:
    path = root / "bodies" / f"{record.name}.npz"
    save_npz_atomic(path, {"joints": record.joints.astype(np.float32),
                           "distances": record.distances.astype(np.float32),
                           "subset": record.subset.astype(np.int64)})
    return path


def write_sequence(root: Path, record: SequenceRecord) -> Path:
    path = root / "sequences" / f"{record.name}.npz"
    save_npz_atomic(path, {
        **_strings(record, ("garment", "body", "motion", "fps")),
        "positions": record.positions.astype(np.float32),
        "joint_transforms": record.joint_transforms.astype(np.float32),
        "motion_features": record.motion_features.astype(np.float32),
        "velocities": record.velocities.astype(np.float32),
        # Collision samples are only used by the collision loss: half precision is
        # ~0.5 mm at 1 m, well below the 4 mm margin, and halves the cache.
        "body_points": record.body_points.astype(np.float16),
        "body_normals": record.body_normals.astype(np.float16)})
    return path


def write_outfit(root: Path, record: OutfitRecord) -> Path:
    path = root / "outfits" / f"{record.name}.npz"
    save_npz_atomic(path, {
        "sequence": np.array(record.sequence), "garments": np.array(record.garments),
        "counts": np.array([len(p) for p in record.start_pos], dtype=np.int64),
        "start_pos": np.concatenate(record.start_pos).astype(np.float32),
        "positions": np.concatenate(record.positions, axis=1).astype(np.float32)})
    return path


def read_outfit(root: Path, name: str) -> OutfitRecord:
    path = root / "outfits" / f"{name}.npz"
    data = load_npz(path, OUTFIT_ARRAYS)
    counts = data["counts"].astype(np.int64)
    garments = [str(g) for g in data["garments"]]
    start, positions = data["start_pos"], data["positions"]
    if (len(counts) != len(garments) or counts.sum() != len(start)
            or positions.ndim != 3 or positions.shape[1] != len(start)):
        raise CacheError(f"{path}: garments, counts, start_pos and positions disagree")
    if not np.isfinite(positions).all():
        raise CacheError(f"{path}: positions contain NaN or inf")
    bounds = np.concatenate([[0], np.cumsum(counts)])
    return OutfitRecord(name=name, sequence=str(data["sequence"]), garments=garments,
                        start_pos=[start[a:b] for a, b in pairwise(bounds)],
                        positions=[positions[:, a:b]
                                   for a, b in pairwise(bounds)])


def read_garment(root: Path, name: str) -> GarmentRecord:
    data = load_npz(root / "garments" / f"{name}.npz", GARMENT_ARRAYS)
    return GarmentRecord(name=name, rest_pos=data["rest_pos"], faces=data["faces"],
                         descriptor=data["descriptor"], topology=str(data["topology"]),
                         garment_type=str(data["garment_type"]), body=str(data["body"]),
                         body_weights=data.get("body_weights"),
                         joint_distances=data.get("joint_distances"),
                         design_pos=data.get("design_pos"))


def read_body(root: Path, name: str) -> BodyRecord:
    data = load_npz(root / "bodies" / f"{name}.npz", BODY_ARRAYS)
    return BodyRecord(name=name, joints=data["joints"], distances=data["distances"],
                      subset=data["subset"])


def read_sequence(root: Path, name: str) -> SequenceRecord:
    path = root / "sequences" / f"{name}.npz"
    data = load_npz(path, SEQUENCE_ARRAYS)
    record = SequenceRecord(
        name=name, garment=str(data["garment"]), body=str(data["body"]),
        motion=str(data["motion"]), fps=float(data["fps"]), positions=data["positions"],
        joint_transforms=data["joint_transforms"], motion_features=data["motion_features"],
        velocities=data["velocities"], body_points=data["body_points"].astype(np.float32),
        body_normals=data["body_normals"].astype(np.float32))
    frames = record.num_frames
    for field_name in ("joint_transforms", "motion_features", "velocities", "body_points",
                       "body_normals"):
        if getattr(record, field_name).shape[0] != frames:
            raise CacheError(f"{path}: {field_name} has {getattr(record, field_name).shape[0]} "
                             f"frames, positions have {frames}")
    if not np.isfinite(record.positions).all():
        raise CacheError(f"{path}: positions contain NaN or inf")
    return record


def read_topology(root: Path, key: str) -> PoolHierarchy:
    return PoolHierarchy.load(root / "topologies" / f"{key}.npz")


def write_topology(root: Path, key: str, hierarchy: PoolHierarchy) -> Path:
    path = root / "topologies" / f"{key}.npz"
    hierarchy.save(path)
    return path


def read_manifest(root: str | Path) -> dict:
    """The cache's manifest, checked for format version.

    Raises:
        CacheError: missing/corrupt manifest or another format version.
    """
    path = Path(root) / "manifest.json"
    if not path.is_file():
        raise CacheError(f"{path}: no prepared cache here (run `gnngarment prepare`)")
    try:
        manifest = json.loads(path.read_text())
    except json.JSONDecodeError as error:
        raise CacheError(f"{path}: corrupt manifest ({error})") from error
    if manifest.get("format_version") != CACHE_FORMAT_VERSION:
        raise CacheError(f"{path}: cache format {manifest.get('format_version')}, expected "
                         f"{CACHE_FORMAT_VERSION}; rebuild it with `gnngarment prepare`")
    return manifest


def verify_cache(root: str | Path) -> list[str]:
    """Check every file listed in the manifest against its sha256.

    Returns:
        Problems found (empty when the cache is intact), each naming a file.
    """
    root = Path(root)
    manifest = read_manifest(root)
    problems = []
    for relative, expected in manifest.get("files", {}).items():
        path = root / relative
        if not path.is_file():
            problems.append(f"{path}: listed in the manifest but missing")
        elif file_hash(path) != expected:
            problems.append(f"{path}: content changed or truncated (sha256 mismatch)")
    return problems


def check_file_sizes(root: str | Path, manifest: dict) -> None:
    """Cheap check (one ``stat`` per file) that every file the manifest lists exists with
    the size it was written with. A manifest written before sizes were recorded (no
    ``sizes`` key) gets the existence check only.

    Raises:
        CacheError: the first missing or resized file (names it).
    """
    root = Path(root)
    sizes = manifest.get("sizes", {})
    for relative in manifest.get("files", {}):
        path = root / relative
        try:
            size = path.stat().st_size
        except OSError:
            raise CacheError(f"{path}: listed in the manifest but missing; rebuild the cache "
                             "with `gnngarment prepare`") from None
        if relative in sizes and size != sizes[relative]:
            raise CacheError(f"{path}: {size} bytes, the manifest says {sizes[relative]} "
                             "(truncated or replaced); rebuild the cache with "
                             "`gnngarment prepare`")


def check_file_hash(root: str | Path, manifest: dict, relative: str) -> None:
    """Check one cache file (``relative`` to ``root``, e.g. ``sequences/x.npz``) against
    the sha256 the manifest lists for it: catches a file swapped for another of the same
    size, which :func:`check_file_sizes` cannot.

    Raises:
        CacheError: not listed, or content differs (names the file).
    """
    path = Path(root) / relative
    expected = manifest.get("files", {}).get(relative)
    if expected is None:
        raise CacheError(f"{path}: not listed in the manifest (added after the cache was "
                         "built); rebuild the cache with `gnngarment prepare`")
    if file_hash(path) != expected:
        raise CacheError(f"{path}: content differs from the manifest (sha256 mismatch): "
                         "changed, truncated or swapped for another file since the cache "
                         "was built; rebuild the cache with `gnngarment prepare`")


def write_manifest(root: str | Path, splits: dict[str, list[str]],
                   sequences: dict[str, dict], extra: dict | None = None) -> dict:
    """Write ``manifest.json`` (the commit point of a build) listing every cache file
    with its sha256 (``files``) and byte size (``sizes``), the splits and per-sequence
    info (garment, body, motion, frames); ``extra`` keys go in as they are (a build's
    ``outfits``: per outfit its split, sequence and garments).

    Raises:
        CacheError: a split names a sequence without a file.
    """
    root = Path(root)
    for split, names in splits.items():
        for name in names:
            if not (root / "sequences" / f"{name}.npz").is_file():
                raise CacheError(f"{root}: split '{split}' lists {name}, which has no file")
    files = {str(path.relative_to(root)): file_hash(path)
             for folder in ("topologies", "garments", "bodies", "sequences", "outfits")
             for path in sorted((root / folder).glob("*.npz"))}
    digest = hashlib.sha256(json.dumps(files, sort_keys=True).encode()).hexdigest()
    sizes = {relative: (root / relative).stat().st_size for relative in files}
    manifest = {"format_version": CACHE_FORMAT_VERSION, "splits": splits,
                "sequences": sequences, "files": files, "sizes": sizes, "hash": digest,
                **(extra or {})}
    # Written last, atomically: the manifest is the cache's commit point.
    atomic_write_bytes(root / "manifest.json",
                       json.dumps(manifest, indent=2, sort_keys=True).encode())
    return manifest
