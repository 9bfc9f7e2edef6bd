"""The plan of a synthetic build: which designs, bodies and motions it pairs into
sequences, and which split each belongs to (deterministic in the config).

Held-out designs, bodies and motions form the validation and test splits: a held-out
sequence combines a held-out design, body and motion of the same split.
"""

from __future__ import annotations

import warnings
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
    tempo (``speed``) and joint-angle (``amplitude``) multipliers; or (``motion ==
    "clip"``) a window of a motion-capture clip: ``seconds`` of ``file`` from ``start``,
    led in from the rest pose over ``lead_in`` seconds and its last pose held ``hold``
    seconds (:func:`planned_motion`)."""

    name: str
    motion: str
    seed: int
    split: str
    speed: float = 1.0
    amplitude: float = 1.0
    file: str = ""
    subject: str = ""
    start: float = 0.0
    seconds: float = 0.0
    digest: str = ""
    lead_in: float = 0.0
    hold: float = 0.0

    @property
    def is_clip(self) -> bool:
        return self.motion == CLIP_MOTION


#: ``MotionPlan.motion`` of a motion-capture window.
CLIP_MOTION = "clip"
#: The fields only a clip window sets (left out of a procedural motion's hash).
CLIP_FIELDS = ("file", "subject", "start", "seconds", "digest", "lead_in", "hold")


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


#: Garment types worn under another (the inner layer of an outfit) and over one.
BOTTOM_TYPES = ("trousers", "skirt")
TOP_TYPES = ("tshirt", "top")


@dataclass(frozen=True)
class OutfitPlan:
    """A layered outfit of the test split: the ``top`` design's garment worn over the
    bottom's, on the body and motion of one of the bottom's test sequences
    (``sequence``, which gives the outfit its motion inputs)."""

    sequence: SequencePlan
    top: DesignPlan

    @property
    def name(self) -> str:
        return f"{self.sequence.name}+{self.top.name}"

    @property
    def garments(self) -> tuple[str, str]:
        """The cache garments, innermost first."""
        return self.sequence.garment, f"{self.top.name}_{self.sequence.body.name}"


def plan_outfits(config: DataConfig, plans: list[SequencePlan] | None = None
                 ) -> list[OutfitPlan]:
    """The ``config.outfits`` layered outfits of a build: on each test body in turn, its
    test bottoms (:data:`BOTTOM_TYPES`) and tops (:data:`TOP_TYPES`) paired in order,
    each pair on every held-out motion of the bottom's test sequences (so the outfit
    and the bottom alone are simulated on the same motion). Deterministic in
    ``config``; ``plans`` is :func:`plan_dataset`'s result where already at hand."""
    if config.outfits == 0:
        return []
    tests = [p for p in (plans if plans is not None else plan_dataset(config))
             if p.split == "test"]
    pairs: list[tuple[DesignPlan, DesignPlan, str]] = []
    for body in dict.fromkeys(p.body.name for p in tests):
        designs = list({p.design.name: p.design for p in tests if p.body.name == body}.values())
        bottoms = [d for d in designs if d.garment_type in BOTTOM_TYPES]
        tops = [d for d in designs if d.garment_type in TOP_TYPES]
        pairs += [(bottom, top, body) for bottom, top in zip(bottoms, tops, strict=False)]
    return [OutfitPlan(sequence, top) for bottom, top, body in pairs[:config.outfits]
            for sequence in tests
            if sequence.design == bottom and sequence.body.name == body]


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
    clips = _clip_motions(config)
    train_motions = [m for m in motions if m.split == "train"]
    train_clips = [m for m in clips if m.split == "train"]
    held_out_clips = {split: [m for m in clips if m.split == split] for split in ("val", "test")}
    next_clip = {"train": 0, "val": 0, "test": 0}
    designs += _extra_designs(config)

    sequences = []
    for design in designs:
        for b, body in enumerate(bodies):
            if design.split == "train" and body.split == "train":
                for j in range(config.motions_per_pair):
                    # The first motions of a pair are the canonical ones (so adding
                    # variants to a config keeps every sequence it already had).
                    motion = train_motions[(b + j + designs.index(design)) % len(train_motions)]
                    if train_clips and j > 0:
                        # With clips, a pair's first motion is procedural (as before) and
                        # the others are clip windows in turn, round-robin over subjects,
                        # so every training window is used about equally often.
                        motion = train_clips[next_clip["train"] % len(train_clips)]
                        next_clip["train"] += 1
                    variant = j * config.motion_variants // config.motions_per_pair
                    if variant and not motion.is_clip:  # a clip is played as recorded
                        motion = _motion_variant(motion, variant, (config.seed, design.seed, b))
                    sequences.append(SequencePlan(f"{design.name}_{body.name}_{motion.name}",
                                                  design, body, motion, "train"))
            elif design.split != "train" and body.split == design.split:
                held_out = [m for m in motions if m.split == design.split]
                chosen = [held_out[designs.index(design) % len(held_out)]] if held_out else []
                # Clip windows in turn, round-robin over subjects: each pair gets its own.
                windows = held_out_clips[design.split]
                for _ in range(min(config.held_out_motions_per_pair, len(windows))):
                    chosen.append(windows[next_clip[design.split] % len(windows)])
                    next_clip[design.split] += 1
                for motion in chosen:
                    sequences.append(SequencePlan(f"{design.name}_{body.name}_{motion.name}",
                                                  design, body, motion, design.split))
    repeated = len(sequences) - len({plan.name for plan in sequences})
    if repeated:
        raise ValueError(
            f"key 'motions_per_pair': {config.motions_per_pair} motions per pair repeat a "
            f"motion ({repeated} sequences planned twice); there are {len(train_motions)} "
            f"train motions, each in {config.motion_variants} variant(s)")
    return sequences


def _clip_motions(config: DataConfig) -> list[MotionPlan]:
    """The windows of the config's motion files as motions, split by subject, each split
    ordered round-robin over its subjects (the first pairs see them all)."""
    from data_prep.motion_windows import clip_windows, find_clips, interleave_by_subject

    if not config.motion_files:
        return []
    windows = clip_windows(find_clips(config.motion_files), config.motion_window_seconds,
                           config.windows_per_clip, config.seed)
    split_of = {**{s: "val" for s in config.splits.val_subjects},
                **{s: "test" for s in config.splits.test_subjects}}
    found = {w.subject for w in windows}
    unknown = sorted(set(split_of) - found)
    if unknown:
        raise ValueError(f"key 'splits': subjects {unknown} have no clip in motion_files "
                         f"(subjects there: {', '.join(sorted(found))})")
    motions = []
    for split in ("train", "val", "test"):
        chosen = interleave_by_subject(
            [w for w in windows if split_of.get(w.subject, "train") == split])
        motions += [MotionPlan(w.name, CLIP_MOTION, 0, split, file=w.file, subject=w.subject,
                               start=w.start, seconds=w.seconds, digest=w.digest,
                               lead_in=config.lead_in_seconds, hold=config.hold_seconds)
                    for w in chosen]
    if not any(m.split == "train" for m in motions):
        raise ValueError("key 'splits': every subject of motion_files is held out; leave "
                         "some for training")
    return motions


def _extra_designs(config: DataConfig) -> list[DesignPlan]:
    """The config's ``extra_train_garments``, then ``extra_val_garments``, then
    ``extra_test_garments`` designs, numbered after the canonical ones and drawn from
    generators of their own (seeded by the config seed and the split), so the draws of
    the canonical plan — designs, motion seeds, splits — stay as they were, and so do
    each split's extra designs when another split's count changes (only their numbers
    follow the train extras)."""
    low, high = config.garment_vertices
    counts = {"train": config.extra_train_garments, "val": config.extra_val_garments,
              "test": config.extra_test_garments}
    designs = []
    k = config.garments
    for index, (split, count) in enumerate(counts.items()):
        # [seed, 1 << 20] is the train extras' generator since before the held-out ones
        # existed (their designs must not change); the others add the split's index.
        key = [config.seed, 1 << 20] + ([index] if index else [])
        rng = np.random.default_rng(key)  # not any canonical draw
        for _ in range(count):
            garment_type = config.garment_types[k % len(config.garment_types)]
            designs.append(DesignPlan(
                name=f"{garment_type}{k:03d}", garment_type=garment_type,
                seed=int(rng.integers(1 << 30)), vertices=int(rng.integers(low, high + 1)),
                fabric=config.fabrics[k % len(config.fabrics)], split=split))
            k += 1
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


def planned_motion(plan: MotionPlan, config: DataConfig, body_model=None, shape=None):
    """The :class:`~gnngarment.body.motion.Motion` a plan stands for (``config`` gives its
    length and frame rate).

    A clip window is read and retargeted onto the body it plays on (``body_model`` in
    ``shape``: a BVH's rest pose and units depend on it), its T-pose reference start
    dropped (:func:`~gnngarment.body.lead_in.trim_reference_pose`), resampled to
    ``config.fps``, cut
    to its window with the root translation made relative to the window's first frame,
    led in from the rest pose and its last pose held (``plan.lead_in``, ``plan.hold``).
    """
    if not plan.is_clip:
        from gnngarment.body.procedural import make_motion

        return make_motion(plan.motion, duration=config.motion_seconds, fps=config.fps,
                           speed=plan.speed, amplitude=plan.amplitude, seed=plan.seed)
    from gnngarment.body.bvh_motion import UnmappedJointsWarning
    from gnngarment.body.lead_in import trim_reference_pose, with_lead_in
    from gnngarment.body.motion import Motion
    from gnngarment.body.motion_io import load_motion_for_body

    if body_model is None:
        raise ValueError(f"{plan.name}: a clip window needs the body it plays on")
    # A file's T-pose reference frame (smeared into its first pose) is not motion: it is
    # dropped at the file's own rate, before resampling blurs it further.
    with warnings.catch_warnings():  # unmapped fingers and eyes: said once by `inspect`
        warnings.simplefilter("ignore", UnmappedJointsWarning)
        clip = trim_reference_pose(load_motion_for_body(plan.file, body_model, shape))
    clip = clip.resample(config.fps)
    first = min(round(plan.start * config.fps), len(clip) - 1)
    window = clip[first:first + round(plan.seconds * config.fps) + 1]
    window = Motion(window.rotations, window.translation - window.translation[:1],
                    config.fps, plan.name)
    if plan.hold > 0:
        held = window[-1:]
        window = Motion.concatenate([window] + [held] * round(plan.hold * config.fps),
                                    name=plan.name)
    return with_lead_in(window, plan.lead_in)

