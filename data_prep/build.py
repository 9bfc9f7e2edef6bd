"""``gnngarment prepare``: build a synthetic CLOTH3D-like dataset and its prepared cache.

Garment designs × bodies × motions are planned deterministically from the config; held-out
designs, bodies and motions form the validation and test splits. Every sequence is
simulated with Newton (:mod:`data_prep.simulate`) in worker processes (Warp's CPU kernels
use one core each), checked by the simulator's quality gates, written in the CLOTH3D
format under ``raw/`` and as a prepared-cache file under ``sequences/``. A sequence
whose cache file exists with the same input hash is skipped, so an interrupted build
(even kill -9) resumes where it stopped; files appear only complete (temp + rename);
``manifest.json`` is written last. The workers run in a local process pool or, with
``executor: ray``, as Ray tasks on a cluster (:mod:`data_prep.executor`); the output is
the same either way.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from data_prep.config import DataConfig
from gnngarment.io.atomic import FolderLock, atomic_write_bytes

#: Bumped when the builder's output changes for the same config (forces a rebuild).
BUILDER_VERSION = 1
#: Garment types whose waist ring is pinned to the pelvis (they hang from the waist).
WAIST_SUPPORTED = ("skirt", "trousers")
#: A garment whose mean distance to the body exceeds this in any frame has slid off
#: (the simulator's gates - NaN, stretch, penetration - do not see a garment falling).
MAX_MEAN_BODY_DISTANCE = 0.15
#: The largest mean downward slide (metres) of the garment relative to the body before a
#: simulated sequence counts as "fell off": a strapless jumpsuit that slid to the feet
#: stays close to the body's shins, so the distance test alone passes it.
MAX_MEAN_DROP = 0.15


def left_the_body(positions: np.ndarray, body_points: np.ndarray,
                  limit: float = MAX_MEAN_BODY_DISTANCE, rest: np.ndarray | None = None,
                  max_drop: float = MAX_MEAN_DROP) -> str:
    """Why a simulated garment is not worn any more, or ``""``: its vertices are on
    average further than ``limit`` from the body, or (given its ``rest`` positions on
    the rest body, which frame 0's body pose starts from) they slid down by more than
    ``max_drop`` on average, beyond the body's own vertical motion.

    Shapes: positions ``(T, N, 3)``, body_points ``(T, M, 3)``, rest ``(N, 3)`` (metres).
    """
    from scipy.spatial import cKDTree

    # The body points under the garment at rest: how far *they* move up or down is the
    # body's own motion (a squat lowers the torso, not the feet).
    if rest is not None:
        under = cKDTree(body_points[0]).query(rest)[1]
        under_height = body_points[:, under, 2].mean(axis=1)   # (T,)
        rest_height = float(rest[:, 2].mean())
    for t in range(len(positions)):
        distance = float(cKDTree(body_points[t]).query(positions[t])[0].mean())
        if distance > limit:
            return (f"garment slid off the body: mean distance {distance:.2f} m > {limit} m "
                    f"at frame {t}")
        if rest is not None:
            body_rise = float(under_height[t] - under_height[0])
            drop = rest_height - float(positions[t, :, 2].mean()) + body_rise
            if drop > max_drop:
                return (f"garment fell down the body: mean drop {drop:.2f} m > {max_drop} m "
                        f"at frame {t}")
    return ""


@dataclass(frozen=True)
class BodyPlan:
    name: str
    shape: dict[str, float]
    split: str  # train | val | test


@dataclass(frozen=True)
class DesignPlan:
    name: str
    garment_type: str
    seed: int
    vertices: int
    fabric: str
    split: str


@dataclass(frozen=True)
class MotionPlan:
    """One motion of the build: a library motion, its seed and, for a variant, its
    tempo (``speed``) and joint-angle (``amplitude``) multipliers."""

    name: str
    motion: str
    seed: int
    split: str
    speed: float = 1.0
    amplitude: float = 1.0


@dataclass(frozen=True)
class SequencePlan:
    name: str
    design: DesignPlan
    body: BodyPlan
    motion: MotionPlan
    split: str

    @property
    def garment(self) -> str:
        return f"{self.design.name}_{self.body.name}"


def _assign(count: int, val: int, test: int) -> list[str]:
    """Split labels for ``count`` items: the last ``test`` are test, the ``val`` before
    them validation, the rest train."""
    if val + test >= count:
        raise ValueError(f"{count} items cannot hold {val} validation + {test} test ones and "
                         "still leave some for training")
    return ["train"] * (count - val - test) + ["val"] * val + ["test"] * test


def plan_dataset(config: DataConfig) -> list[SequencePlan]:
    """Every sequence of the build, deterministic in ``config``.

    Train sequences pair every train design with every train body and
    ``motions_per_pair`` train motions; a validation (test) sequence pairs a held-out
    design with a held-out body and a held-out motion of the same split.
    """
    from gnngarment.body.anny_model import ANNY_PRESETS, sample_anny_shapes

    rng = np.random.default_rng(config.seed)
    splits = config.splits
    body_split = _assign(config.bodies, splits.val_bodies, splits.test_bodies)
    shapes = [asdict(ANNY_PRESETS[name]) for name in config.body_presets]
    shapes += [asdict(s) for s in sample_anny_shapes(max(config.bodies - len(shapes), 0),
                                                     seed=config.seed)]
    bodies = [BodyPlan(f"body{k:02d}", shapes[k], body_split[k]) for k in range(config.bodies)]

    design_split = _assign(config.garments, splits.val_garments, splits.test_garments)
    low, high = config.garment_vertices
    designs = []
    for k in range(config.garments):
        garment_type = config.garment_types[k % len(config.garment_types)]
        designs.append(DesignPlan(
            name=f"{garment_type}{k:03d}", garment_type=garment_type,
            seed=int(rng.integers(1 << 30)), vertices=int(rng.integers(low, high + 1)),
            fabric=config.fabrics[k % len(config.fabrics)], split=design_split[k]))
    motion_split = _assign(len(config.motions), splits.val_motions, splits.test_motions)
    motions = [MotionPlan(f"{name}{k:02d}", name, int(rng.integers(1 << 30)), motion_split[k])
               for k, name in enumerate(config.motions)]
    train_motions = [m for m in motions if m.split == "train"]

    sequences = []
    for design in designs:
        for b, body in enumerate(bodies):
            if design.split == "train" and body.split == "train":
                for j in range(config.motions_per_pair):
                    # The first motions of a pair are the canonical ones (so adding
                    # variants to a config keeps every sequence it already had).
                    motion = train_motions[(b + j + designs.index(design)) % len(train_motions)]
                    variant = j * config.motion_variants // config.motions_per_pair
                    if variant:
                        motion = _motion_variant(motion, variant, (config.seed, design.seed, b))
                    sequences.append(SequencePlan(f"{design.name}_{body.name}_{motion.name}",
                                                  design, body, motion, "train"))
            elif design.split != "train" and body.split == design.split:
                held_out = [m for m in motions if m.split == design.split]
                motion = held_out[designs.index(design) % len(held_out)]
                sequences.append(SequencePlan(f"{design.name}_{body.name}_{motion.name}",
                                              design, body, motion, design.split))
    repeated = len(sequences) - len({plan.name for plan in sequences})
    if repeated:
        raise ValueError(
            f"key 'motions_per_pair': {config.motions_per_pair} motions per pair repeat a "
            f"motion ({repeated} sequences planned twice); there are {len(train_motions)} "
            f"train motions, each in {config.motion_variants} variant(s)")
    return sequences


#: Variant tempo and joint-angle multipliers are drawn from these ranges (the amplitude
#: stays under the library's tested 1.2 after its own ±10 % jitter).
VARIANT_SPEED = (0.75, 1.35)
VARIANT_AMPLITUDE = (0.7, 1.05)


def _motion_variant(motion: MotionPlan, variant: int, key: tuple[int, ...]) -> MotionPlan:
    """Variant ``variant`` (>= 1) of a train motion for one (design, body) pair (``key``):
    the same library motion at its own tempo, amplitude and seed, so every sequence
    that has one moves differently. Drawn from a generator of its own, so the draws of
    the canonical plan are unchanged."""
    rng = np.random.default_rng([*key, motion.seed, variant])
    return MotionPlan(f"{motion.name}v{variant}", motion.motion, int(rng.integers(1 << 30)),
                      motion.split, speed=round(float(rng.uniform(*VARIANT_SPEED)), 3),
                      amplitude=round(float(rng.uniform(*VARIANT_AMPLITUDE)), 3))


def planned_motion(plan: MotionPlan, config: DataConfig):
    """The :class:`~gnngarment.body.motion.Motion` a plan stands for (``config`` gives its
    length and frame rate)."""
    from gnngarment.body.procedural import make_motion

    return make_motion(plan.motion, duration=config.motion_seconds, fps=config.fps,
                       speed=plan.speed, amplitude=plan.amplitude, seed=plan.seed)


#: Config keys that only decide *which* garments, bodies and motions are planned: their
#: effect on a sequence is all in its plan (hashed with it), so changing them (e.g. more
#: motions per pair) keeps every sequence and drape already built.
PLAN_KEYS = ("seed", "garment_types", "garments", "garment_vertices", "bodies",
             "body_presets", "motions", "motions_per_pair", "motion_variants", "fabrics",
             "splits")
#: Config keys that decide nothing a worker computes.
PLACE_KEYS = ("output", "workers", "simulation", "executor", "ray_address")


def content_inputs(config: DataConfig, settings: Any) -> dict[str, Any]:
    """What every sequence's and drape's content depends on besides its own plan: not
    where the dataset lives, how many processes build it or where, the path of the
    simulation file (its ``settings`` are hashed), nor what only chooses the plans."""
    content = {k: v for k, v in asdict(config).items() if k not in PLACE_KEYS + PLAN_KEYS}
    return {"builder": BUILDER_VERSION, "config": content, "simulation": asdict(settings)}


def sequence_inputs_hash(inputs: dict[str, Any], plan: SequencePlan) -> str:
    """The hash a built sequence is recorded with (its ``.hash`` file). A canonical
    motion (tempo and amplitude 1) is hashed without those two fields."""
    fields = asdict(plan)
    fields["motion"] = {key: value for key, value in fields["motion"].items()
                        if key not in ("speed", "amplitude") or value != 1.0}
    return _hash({**inputs, "plan": fields})


def _hash(payload: Any) -> str:
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()


# ------------------------------------------------------------------------- workers
_WORKER: dict[str, Any] = {}


def _body_model():
    if "body" not in _WORKER:
        from gnngarment.body.anny_model import AnnyBodyModel

        _WORKER["body"] = AnnyBodyModel()
    return _WORKER["body"]


def _shape(plan: BodyPlan):
    from gnngarment.body.anny_model import AnnyShape

    return AnnyShape(**plan.shape)


def prepare_body(root: Path, plan: BodyPlan, config: DataConfig) -> None:
    """Write ``bodies/<name>.npz`` (rest joints, D, subset)."""
    from gnngarment.data.body_inputs import body_shape_inputs
    from gnngarment.data.cache import BodyRecord, write_body

    inputs = body_shape_inputs(_body_model(), _shape(plan), config.body_vertices)
    write_body(root, BodyRecord(name=plan.name, joints=inputs.joints,
                                distances=inputs.distances, subset=inputs.subset))


def is_strapless(style: Any) -> bool:
    """Whether a sampled style has no straps or sleeves to hang from (a tube top, a
    strapless dress or jumpsuit)."""
    return "strapless" in (getattr(style, "sleeves", None), getattr(style, "kind", None))


@dataclass(frozen=True)
class GarmentDesign:
    """A design fitted to a body's rest pose, before draping.

    Attributes:
        pos: ``(N, 3)`` design positions [m]; faces ``(F, 3)``.
        pinned: ``(P,)`` vertices held by the body: the waist ring of a skirt or trousers,
            the elastic top band of a strapless design; empty otherwise.
        pin_joint: the joint whose rigid motion the pinned vertices follow (-1: none).
    """

    pos: np.ndarray
    faces: np.ndarray
    pinned: np.ndarray
    pin_joint: int


def make_garment(design: DesignPlan, body: BodyPlan) -> GarmentDesign:
    """The design fitted to the body's rest pose (undraped).

    A design is its type, a style drawn from the design's seed and a resolution: the
    same design on every body (fitted to each), as CLOTH3D refits a garment per body.
    Skirts and trousers hang from a waist ring that follows the pelvis; a strapless top,
    dress or jumpsuit has an elastic top band that follows the chest joint it sits on
    (without it, 17 of 74 benchmark sequences slid down the body).
    """
    from data_prep.garments import GARMENT_TYPES, BodyFrame
    from data_prep.garments import make_garment as build_garment

    body_model = _body_model()
    rest = body_model.rest(_shape(body))
    frame = BodyFrame(vertices=rest.vertices.numpy(), faces=rest.faces,
                      joints=rest.joints.numpy())
    style = GARMENT_TYPES[design.garment_type][0].sample(np.random.default_rng(design.seed))
    garment = build_garment(frame, design.garment_type, style,
                            target_vertices=design.vertices, seed=design.seed,
                            name=design.name)
    band = np.asarray(garment.pin_candidates, dtype=np.int64)
    if design.garment_type in WAIST_SUPPORTED:
        return GarmentDesign(garment.pos, garment.faces, band, 0)
    if is_strapless(style):
        from gnngarment.body.weight_transfer import transfer_body_weights

        weights = transfer_body_weights(garment.pos[band], rest.vertices.numpy(),
                                        body_model.skinning_weights())
        return GarmentDesign(garment.pos, garment.faces, band, int(weights.sum(0).argmax()))
    return GarmentDesign(garment.pos, garment.faces, np.zeros(0, dtype=np.int64), -1)


def read_pins(root: Path, garment: str) -> tuple[np.ndarray, int]:
    """The pinned vertices ``(P,)`` of a cache garment and the joint they follow."""
    pins = json.loads((root / "garments" / f"{garment}.pins.json").read_text())
    return np.asarray(pins["vertices"], dtype=np.int64), int(pins["joint"])


def drape_and_prepare_garment(task: tuple[str, DesignPlan, BodyPlan, DataConfig, str]
                              ) -> dict[str, Any]:
    """Worker: fit a design to a body, drape it on the still rest body (the template,
    DESIGN.md), and write ``garments/<design>_<body>.npz`` (rest_pos = the drape,
    design_pos = the design), its pins and its topology. Returns a status dict (never
    raises for a failed drape: the garment and its sequences are reported and left out).
    """
    root_text, design, body, config, inputs_hash = task
    root = Path(root_text)
    name = f"{design.name}_{body.name}"
    started = time.perf_counter()
    try:
        import torch

        from data_prep.simulate import SimulationFailed, drape_garment, load_simulation_settings
        from gnngarment.body.weight_transfer import transfer_body_weights
        from gnngarment.data.cache import (
            GarmentRecord,
            topology_key,
            write_garment,
            write_topology,
        )
        from gnngarment.geometry.prepare import GarmentPreparationConfig, prepare_garment

        torch.set_num_threads(1)
        body_model = _body_model()
        rest = body_model.rest(_shape(body))
        body_vertices = rest.vertices.numpy()
        made = make_garment(design, body)
        try:
            drape = drape_garment(made.pos, made.faces, body_vertices, body_model.faces,
                                  config.fps, fabric=design.fabric,
                                  pinned=made.pinned if len(made.pinned) else None,
                                  settings=load_simulation_settings(config.simulation),
                                  max_frames=config.drape_frames,
                                  rest_speed=config.drape_rest_speed)
        except SimulationFailed as error:
            return _left_out(root, name, inputs_hash, f"drape: {error}", started, "garments")
        samples = body_model.feature_vertex_indices(config.collision_points)
        off = left_the_body(drape.positions[None], body_vertices[samples][None],
                            rest=made.pos)
        if off:
            return _left_out(root, name, inputs_hash, f"drape: {off}", started, "garments")
        pos = drape.positions.astype(np.float64)
        prepared = prepare_garment(pos, made.faces, GarmentPreparationConfig(
            levels=config.levels, landmarks=config.landmarks), source=name)
        key = topology_key(made.faces)
        if not (root / "topologies" / f"{key}.npz").is_file():
            write_topology(root, key, prepared.hierarchy)
        weights = transfer_body_weights(pos, body_vertices, body_model.skinning_weights())
        atomic_write_bytes(root / "garments" / f"{name}.pins.json", json.dumps(
            {"vertices": made.pinned.tolist(), "joint": made.pin_joint}).encode())
        write_garment(root, GarmentRecord(name=name, rest_pos=pos, faces=made.faces,
                                          descriptor=prepared.descriptor, topology=key,
                                          garment_type=design.garment_type, body=body.name,
                                          body_weights=weights, design_pos=made.pos))
        atomic_write_bytes(root / "garments" / f"{name}.hash", inputs_hash.encode())
        return {"name": name, "ok": True, "vertices": len(pos), "faces": len(made.faces),
                "pinned": len(made.pinned), "drape_frames": drape.frames,
                "drape_settled": drape.settled,
                "drape_last_speed_mm": 1000 * drape.last_speed,
                "drape_mean_displacement_mm": 1000 * drape.mean_displacement,
                "seconds": time.perf_counter() - started}
    except Exception as error:  # a broken design on this body: report, don't kill the build
        return _crashed(name, error, started)


def simulate_sequence(task: tuple[str, SequencePlan, DataConfig, str]) -> dict[str, Any]:
    """Worker: pose, simulate, check and write one sequence. Returns a status dict
    (never raises for a failed simulation: that sequence is reported and left out)."""
    root_text, plan, config, inputs_hash = task
    root = Path(root_text)
    started = time.perf_counter()
    try:
        import torch

        from data_prep.cloth3d import write_sequence as write_cloth3d
        from data_prep.simulate import SimulationFailed, load_simulation_settings, simulate_garment
        from gnngarment.body.features import motion_features
        from gnngarment.data.cache import SequenceRecord, read_garment, write_sequence
        from gnngarment.geometry.normals import vertex_normals

        torch.set_num_threads(1)
        body_model = _body_model()
        shape = _shape(plan.body)
        motion = planned_motion(plan.motion, config)
        with torch.no_grad():
            posed = body_model.pose(motion, shape)
        body_vertices = posed.vertices.numpy()
        transforms = posed.joint_transforms.numpy()
        garment = read_garment(root, plan.garment)
        pinned, pin_joint = read_pins(root, plan.garment)
        pin_targets = None
        if len(pinned):
            # A waist ring or top band follows its joint rigidly.
            rest_h = np.concatenate([garment.rest_pos[pinned], np.ones((len(pinned), 1))], 1)
            pin_targets = np.einsum("tab,pb->tpa", transforms[:, pin_joint], rest_h)[..., :3]
        settings = load_simulation_settings(config.simulation)
        if config.settle_frames >= 0:
            settings.settle_frames = config.settle_frames
        result = simulate_garment(garment.rest_pos, garment.faces, body_vertices,
                                  body_model.faces, config.fps, fabric=plan.design.fabric,
                                  pinned=pinned if len(pinned) else None,
                                  pin_targets=pin_targets, settings=settings)
        velocities = body_model.subset_velocities(posed, config.fps, config.body_vertices).numpy()
        samples = body_model.feature_vertex_indices(config.collision_points)
        normals = np.stack([vertex_normals(v, body_model.faces)[samples] for v in body_vertices])
        features = motion_features(motion).numpy()
        off = left_the_body(result.positions, body_vertices[:, samples],
                            rest=garment.rest_pos)
        if off:
            return _left_out(root, plan.name, inputs_hash, off, started)
        record = SequenceRecord(
            name=plan.name, garment=plan.garment, body=plan.body.name, motion=plan.motion.name,
            fps=config.fps, positions=result.positions, joint_transforms=transforms,
            motion_features=features, velocities=velocities,
            body_points=body_vertices[:, samples], body_normals=normals)
        # Raw sequence in the CLOTH3D layout (same reader path as real CLOTH3D data).
        translation = motion.translation.astype(np.float64)
        write_cloth3d(root / "raw" / plan.name, {
            "poses": motion.rotations.reshape(len(motion), -1), "trans": translation,
            "shape": np.zeros(10), "gender": round(plan.body.shape["gender"]),
            "zrot": 0.0, "outfit": {plan.design.garment_type: {"fabric": plan.design.fabric}},
            "body_model": "anny", "anny_phenotype": plan.body.shape,
        }, {plan.design.garment_type: (garment.rest_pos, garment.faces,
                                       result.positions - translation[:, None, :])})
        path = write_sequence(root, record)
        # The input hash lives beside the file: the next build skips this sequence.
        atomic_write_bytes(path.parent / f"{plan.name}.hash", inputs_hash.encode())
        return {"name": plan.name, "ok": True, "frames": len(motion),
                "seconds": time.perf_counter() - started,
                "seconds_per_frame": result.seconds_per_frame, "attempts": result.attempts,
                "max_stretch": float(np.nanmax(result.quality.max_stretch)),
                "max_inside_pct": 100 * float(np.nanmax(result.quality.inside_fraction))}
    except SimulationFailed as error:
        return _left_out(root, plan.name, inputs_hash, str(error), started)
    except Exception as error:  # a broken garment or body: report, don't kill the build
        return _crashed(plan.name, error, started)


def _crashed(name: str, error: Exception, started: float) -> dict[str, Any]:
    """The status dict of a worker task that raised: the error and where it was raised."""
    import traceback

    where = traceback.extract_tb(error.__traceback__)[-1]
    return {"name": name, "ok": False,
            "reason": f"{type(error).__name__}: {error} ({Path(where.filename).name}:"
                      f"{where.lineno})", "seconds": time.perf_counter() - started}


def _left_out(root: Path, name: str, inputs_hash: str, reason: str,
              started: float, kind: str = "sequences") -> dict[str, Any]:
    """Record a sequence (``kind="garments"``: a garment's drape) that failed its quality
    gates (with its input hash, so that a resumed build does not simulate it again) and
    return its status dict."""
    folder = root / kind
    folder.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(folder / f"{name}.failed",
                       json.dumps({"inputs_hash": inputs_hash, "reason": reason}).encode())
    return {"name": name, "ok": False, "reason": reason,
            "seconds": time.perf_counter() - started}


def _known_failure(root: Path, name: str, inputs_hash: str,
                   folder: str = "sequences") -> str | None:
    """The recorded reason a sequence (or, with ``folder="garments"``, a garment's drape)
    with these inputs failed before, if any."""
    path = root / folder / f"{name}.failed"
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return record.get("reason") if record.get("inputs_hash") == inputs_hash else None


def _intact_npz(path: Path) -> bool:
    """Whether ``path`` is a whole ``.npz``: its zip directory reads and every member
    matches its CRC (a truncated or damaged file is rebuilt, not counted as built)."""
    import zipfile

    try:
        with zipfile.ZipFile(path) as archive:
            return archive.testzip() is None
    except (OSError, EOFError, zipfile.BadZipFile):
        return False


def _garment_done(root: Path, name: str, inputs_hash: str) -> bool:
    hash_file = root / "garments" / f"{name}.hash"
    return ((root / "garments" / f"{name}.npz").is_file()
            and (root / "garments" / f"{name}.pins.json").is_file()
            and hash_file.is_file() and hash_file.read_text() == inputs_hash
            and _intact_npz(root / "garments" / f"{name}.npz"))


def _garment_summary(root: Path, name: str) -> dict[str, Any]:
    """What the build report says of a garment draped by an earlier run."""
    from gnngarment.data.cache import read_garment

    record = read_garment(root, name)
    shift = (np.linalg.norm(record.rest_pos - record.design_pos, axis=1).mean()
             if record.design_pos is not None else float("nan"))
    return {"name": name, "ok": True, "vertices": len(record.rest_pos),
            "faces": len(record.faces), "pinned": len(read_pins(root, name)[0]),
            "drape_mean_displacement_mm": 1000 * float(shift)}


def _sequence_done(root: Path, name: str, inputs_hash: str) -> bool:
    hash_file = root / "sequences" / f"{name}.hash"
    return ((root / "sequences" / f"{name}.npz").is_file() and hash_file.is_file()
            and hash_file.read_text() == inputs_hash
            and _intact_npz(root / "sequences" / f"{name}.npz"))


def build_dataset(config: DataConfig, workers: int | None = None,
                  log: Callable[[str], None] = print) -> dict[str, Any]:
    """Build (or resume) the dataset of ``config`` under ``config.output``. Validation and
    test sequences are simulated before the training ones.

    Returns:
        The build report (also written to ``build_report.json``).

    Raises:
        FolderBusyError: another build holds ``config.output``.
        RayMissingError: ``config.executor`` is ``ray`` and Ray is not installed.
    """
    if config.executor == "ray":  # before any work, not after the bodies
        from data_prep.ray_executor import import_ray

        import_ray()
    root = Path(config.output)
    with FolderLock(root, "`gnngarment prepare`") as lock:
        # A killed build can leave the temporary file of a write it did not finish: with
        # the lock held no other build is writing here, so those (and only those names)
        # are stale.
        lock.remove_stale_temporaries(CACHE_FOLDERS)
        return _build_locked(root, config, workers, log, lock)


#: The folders a build writes (stale temporary files are looked for only there).
CACHE_FOLDERS = ("raw", "garments", "sequences", "topologies", "bodies", ".")


def _lost(task: tuple, error: Exception) -> dict[str, Any]:
    """The status of a task whose worker process died more often than Ray retries it:
    left out of this build, not recorded as failed (the next build tries it again)."""
    plan = task[1]
    name = plan.name if isinstance(plan, SequencePlan) else f"{plan.name}_{task[2].name}"
    return {"name": name, "ok": False, "reason": f"worker lost: {type(error).__name__}",
            "seconds": math.nan}


def _build_locked(root: Path, config: DataConfig, workers: int | None,
                  log: Callable[[str], None], lock: FolderLock) -> dict[str, Any]:
    from tqdm import tqdm

    from data_prep.executor import make_executor
    from data_prep.simulate import load_simulation_settings
    from gnngarment.data.cache import write_manifest

    started = time.perf_counter()
    plans = plan_dataset(config)
    settings = load_simulation_settings(config.simulation)
    base_hash = content_inputs(config, settings)

    bodies = {p.body.name: p.body for p in plans}
    for plan in tqdm(bodies.values(), desc="bodies", unit="body"):
        prepare_body(root, plan, config)
    garments: dict[str, tuple[DesignPlan, BodyPlan]] = {}
    for plan in plans:
        garments.setdefault(plan.garment, (plan.design, plan.body))
    drape_tasks, garment_info, failed_garments = [], {}, {}
    for name, (design, body) in garments.items():
        garment_hash = _hash({**base_hash, "design": asdict(design), "body": asdict(body)})
        if _garment_done(root, name, garment_hash):
            garment_info[name] = _garment_summary(root, name)
            continue
        reason = _known_failure(root, name, garment_hash, folder="garments")
        if reason is not None:
            failed_garments[name] = reason
            continue
        drape_tasks.append((str(root), design, body, config, garment_hash))

    workers = workers or config.workers or None
    log(f"{len(garments)} garments planned: {len(garment_info)} already draped, "
        f"{len(failed_garments)} failed before with the same inputs, {len(drape_tasks)} to "
        "drape on their rest bodies")
    results: list[dict[str, Any]] = []
    with make_executor(config.executor, workers, config.ray_address) as executor:
        if executor.describe():
            log(executor.describe())
        if drape_tasks:
            _warm_up_kernels(log)
            for result in tqdm(executor.imap_unordered(drape_and_prepare_garment, drape_tasks,
                                                       lost=_lost),
                               total=len(drape_tasks), desc="draping", unit="garment"):
                if result["ok"]:
                    garment_info[result["name"]] = result
                else:
                    failed_garments[result["name"]] = result["reason"]
                    log(f"garment {result['name']} left out: {result['reason']}")

        tasks, skipped = [], 0
        known_failures: dict[str, str] = {}
        for plan in plans:
            if plan.garment in failed_garments:
                continue
            inputs_hash = sequence_inputs_hash(base_hash, plan)
            if _sequence_done(root, plan.name, inputs_hash):
                skipped += 1
                continue
            reason = _known_failure(root, plan.name, inputs_hash)
            if reason is not None:  # same inputs failed before: it would fail again
                known_failures[plan.name] = reason
                continue
            tasks.append((str(root), plan, config, inputs_hash))
        # Held-out sequences first: an interrupted or still-running build can already be
        # evaluated on them (sorted stably, so each group keeps the plan's order).
        tasks.sort(key=lambda task: task[1].split == "train")
        log(f"{len(plans)} sequences planned: {skipped} already built, {len(known_failures)} "
            f"failed before with the same inputs, {len(tasks)} to simulate with "
            f"{executor.parallelism(len(tasks))} worker(s)")
        if tasks:
            if not drape_tasks:
                _warm_up_kernels(log)
            bar = tqdm(executor.imap_unordered(simulate_sequence, tasks, lost=_lost),
                       total=len(tasks), desc="simulating", unit="sequence")
            for result in bar:
                results.append(result)
                if not result["ok"]:
                    log(f"sequence {result['name']} left out: {result['reason']}")
    # A worker killed mid-write (and retried) left a hidden temporary file; every worker
    # has stopped, so it is stale.
    lock.remove_stale_temporaries(CACHE_FOLDERS)

    failed = known_failures | {r["name"]: r["reason"] for r in results if not r["ok"]}
    built = [p for p in plans if p.garment not in failed_garments and p.name not in failed
             and (root / "sequences" / f"{p.name}.npz").is_file()]
    splits = {split: [p.name for p in built if p.split == split]
              for split in ("train", "val", "test")}
    sequences = {p.name: {"garment": p.garment, "body": p.body.name, "motion": p.motion.name,
                          "frames": round(config.motion_seconds * config.fps),
                          "garment_type": p.design.garment_type, "fabric": p.design.fabric}
                 for p in built}
    for plan in built:  # the frame count from the motion actually made
        done = next((r for r in results if r["name"] == plan.name and r["ok"]), None)
        if done is not None:
            sequences[plan.name]["frames"] = done["frames"]
        else:
            from gnngarment.data.cache import read_sequence

            sequences[plan.name]["frames"] = read_sequence(root, plan.name).num_frames
    manifest = write_manifest(root, splits, sequences, extra={
        "builder_version": BUILDER_VERSION, "config": asdict(config),
        "fabric_density": 0.2})
    report = {
        "output": str(root), "seconds": time.perf_counter() - started,
        "planned": len(plans), "skipped_existing": skipped, "simulated": len(results),
        "failed_sequences": failed, "failed_garments": failed_garments,
        "losses_by_reason": losses_by_reason(failed, failed_garments, plans),
        "splits": {k: len(v) for k, v in splits.items()},
        "seconds_per_frame": float(np.mean([r["seconds_per_frame"] for r in results
                                            if r["ok"]])) if any(r["ok"] for r in results)
        else None,
        "manifest_hash": manifest["hash"], "garments": garment_info,
    }
    atomic_write_bytes(root / "build_report.json", json.dumps(report, indent=2).encode())
    return report


#: Reason a planned sequence was lost → the words that identify it in its message.
LOSS_REASONS = {
    "drape failed": ("drape:",),
    "left the body": ("slid off the body",),
    "fell down the body": ("fell down the body",),
    "edge stretch": ("stretch",),
    "inside the body": ("inside",),
    "not finite": ("non-finite",),
}


def losses_by_reason(failed_sequences: dict[str, str], failed_garments: dict[str, str],
                     plans: list[SequencePlan]) -> dict[str, int]:
    """How many planned sequences each kind of failure removed (a failed garment drape
    removes all of its sequences), plus ``planned`` and ``lost`` in total."""
    counts: dict[str, int] = {}

    def count(reason: str) -> None:
        kind = next((k for k, words in LOSS_REASONS.items()
                     if any(w in reason for w in words)), "other")
        counts[kind] = counts.get(kind, 0) + 1

    for plan in plans:
        if plan.garment in failed_garments:
            count(failed_garments[plan.garment])
        elif plan.name in failed_sequences:
            count(failed_sequences[plan.name])
    return {"planned": len(plans), "lost": sum(counts.values()), **counts}


def _warm_up_kernels(log: Callable[[str], None]) -> None:
    """Compile Warp's kernels once in this process (a tiny simulation), so the workers
    load them from the on-disk kernel cache instead of all compiling at the same time
    (~25-45 s on an empty cache, seconds afterwards)."""
    import trimesh

    from data_prep.garments.skirt import flared_skirt
    from data_prep.simulate import SimulationSettings, simulate_garment

    started = time.perf_counter()
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.1)
    body = np.repeat(np.asarray(sphere.vertices)[None], 2, axis=0)
    pos, faces = flared_skirt(60, waist_radius=0.12, hem_radius=0.2, length=0.1,
                              waist_height=0.05)
    simulate_garment(pos, faces, body, np.asarray(sphere.faces), 30.0,
                     settings=SimulationSettings(settle_frames=0, max_retries=0,
                                                 max_edge_stretch=100.0,
                                                 max_inside_fraction=1.0))
    log(f"simulation kernels ready ({time.perf_counter() - started:.0f} s)")
