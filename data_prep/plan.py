"""The plan of a synthetic build: which designs, bodies and motions it pairs into
sequences, and which split each belongs to (deterministic in the config).

Held-out designs, bodies and motions form the validation and test splits: a held-out
sequence combines a held-out design, body and motion of the same split.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from data_prep.config import DataConfig


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
    designs += _extra_train_designs(config)

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


def _extra_train_designs(config: DataConfig) -> list[DesignPlan]:
    """The config's ``extra_train_garments`` designs, numbered after the canonical ones
    and drawn from a generator of their own (seeded by the config seed), so the draws
    of the canonical plan — designs, motion seeds, splits — stay as they were."""
    rng = np.random.default_rng([config.seed, 1 << 20])  # not any canonical draw
    low, high = config.garment_vertices
    designs = []
    for k in range(config.garments, config.garments + config.extra_train_garments):
        garment_type = config.garment_types[k % len(config.garment_types)]
        designs.append(DesignPlan(
            name=f"{garment_type}{k:03d}", garment_type=garment_type,
            seed=int(rng.integers(1 << 30)), vertices=int(rng.integers(low, high + 1)),
            fabric=config.fabrics[k % len(config.fabrics)], split="train"))
    return designs


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

