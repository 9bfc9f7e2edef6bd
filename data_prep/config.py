"""Settings of a dataset build (``configs/data/*.yaml``)."""

from __future__ import annotations

from dataclasses import dataclass, field

#: Largest values a build accepts: a sequence's frames are simulated and held in memory
#: whole (``motion_seconds · fps`` frames of the body and garment per worker).
UPPER_LIMITS = {"fps": 240.0, "motion_seconds": 60.0, "motion_window_seconds": 60.0}


@dataclass
class SplitConfig:
    """How many garment designs, bodies and motions each held-out split gets. Held-out
    items never appear in training; validation and test sequences combine a held-out
    design, body and motion (everything unseen at once).

    ``val_subjects``/``test_subjects`` hold out the clips of ``motion_files`` by
    performer (:func:`data_prep.motion_windows.clip_subject`): a held-out subject's
    windows are motions of that split only; every other subject's are for training."""

    val_garments: int = 1
    test_garments: int = 2
    val_bodies: int = 1
    test_bodies: int = 1
    val_motions: int = 1
    test_motions: int = 1
    val_subjects: list[str] = field(default_factory=list)
    test_subjects: list[str] = field(default_factory=list)


@dataclass
class DataConfig:
    """A synthetic CLOTH3D-like dataset.

    Attributes:
        output: cache folder (``raw/`` holds the CLOTH3D-format sequences).
        seed: seeds every sampler of the build.
        garment_types: garment types to cycle through.
        garments: garment designs in total (train + held out).
        extra_train_garments: further train designs, drawn after the canonical plan
            from a generator of their own, so adding them keeps every design, body,
            motion and split the config had (the same validation and test sequences).
        extra_val_garments, extra_test_garments: further held-out designs, drawn the
            same way after the extra train designs (numbered after them: growing
            ``extra_train_garments`` later renames these), each paired with the split's
            bodies and held-out motions like the canonical ones, so a split can grow
            without changing training or the sequences it had.
        garment_vertices: [min, max] target vertex count of a garment.
        bodies: body shapes in total; named presets are used first, then samples.
        body_presets: Anny presets to use first.
        motions: procedural motion names (train + held out; held-out ones are the last).
        motion_seconds: length of every motion (s); fps: frames per second.
        motions_per_pair: train motions simulated per (design, body) pair.
        motion_files: motion-capture clips (``.bvh``/``.npz`` files, or folders of
            them) used besides the procedural ``motions``, cut into windows; relative
            paths start at the working folder (the repository root for ``make``).
        motion_window_seconds: length of a clip's window (s); a shorter clip is one
            window, the whole clip. windows_per_clip: most windows cut from one clip.
        lead_in_seconds: a clip window starts at the rest pose (the draped template)
            and blends into its first pose over this long
            (:func:`gnngarment.body.lead_in.with_lead_in`): mocap windows start
            mid-motion, and a jump from the rest pose is an impulse no cloth follows.
        hold_seconds: the body holds a window's last pose this long after it, so the
            garment's swing after the body stops is in the data.
        held_out_motions_per_pair: clip windows per held-out (design, body) pair, beside
            the pair's procedural held-out motion (when the split has one).
        motion_variants: versions of every train motion (1 = the canonical one only);
            each further variant has its own seeded tempo and amplitude, and takes the
            last ``(variants - 1) / variants`` of a pair's motions.
        fabrics: fabrics to cycle through (CLOTH3D names).
        body_vertices: ``N_b'`` feature subset size; collision_points: body samples
            stored per frame for the collision loss and rate.
        levels, landmarks: pooling levels and Nyström landmarks of the topology cache.
        simulation: simulation settings file (``configs/simulation.yaml``).
        settle_frames: overrides the simulation file's settle frames (-1 = keep): frames
            simulated on the still first pose before a sequence's motion. Sequences
            start from the draped template, so 0 is the usual value.
        drape_frames: frame cap of the drape that makes every template (the design
            settled on the still rest body).
        drape_rest_speed: a drape is at rest when no vertex moves this far in a frame [m].
        workers: simulation processes (0 = one per core); with ``executor: ray`` the most
            tasks in flight (0 = as many as the cluster has CPUs).
        executor: where the workers run: ``local`` (a process pool on this machine) or
            ``ray`` (Ray tasks; needs ``pip install -e .[ray]``). The output is the same.
        ray_address: the Ray cluster to join with ``executor: ray`` (``auto``,
            ``HOST:6379``, ``ray://HOST:10001``); empty: the one ``RAY_ADDRESS`` names,
            else one started with ``ray start`` on this machine, else a new Ray here.
        outfits: layered test outfits to simulate besides the sequences (0: none): a
            test bottom (trousers, skirt) and a test top (T-shirt, top) draped on the
            same test body, both garments in one Newton scene on each held-out motion
            of the bottom's test sequences (:func:`data_prep.plan.plan_outfits`);
            ``gnngarment evaluate`` reports them per garment and by inter-garment
            penetration (docs/outfits.md).
        splits: held-out counts.
    """

    output: str = "data/demo"
    seed: int = 0
    garment_types: list[str] = field(default_factory=lambda: [
        "skirt", "dress", "jumpsuit", "tshirt", "trousers", "top"])
    garments: int = 12
    extra_train_garments: int = 0
    extra_val_garments: int = 0
    extra_test_garments: int = 0
    garment_vertices: list[int] = field(default_factory=lambda: [900, 1500])
    bodies: int = 4
    body_presets: list[str] = field(default_factory=list)
    motions: list[str] = field(default_factory=lambda: ["walk", "squat", "arm_raise", "twist",
                                                        "run", "wave"])
    motion_seconds: float = 2.0
    fps: float = 30.0
    motions_per_pair: int = 1
    motion_files: list[str] = field(default_factory=list)
    motion_window_seconds: float = 2.0
    windows_per_clip: int = 2
    lead_in_seconds: float = 0.5
    hold_seconds: float = 0.0
    held_out_motions_per_pair: int = 1
    motion_variants: int = 1
    fabrics: list[str] = field(default_factory=lambda: ["cotton", "silk", "denim", "leather"])
    body_vertices: int = 128
    collision_points: int = 2048
    levels: int = 3
    landmarks: int = 64
    simulation: str = "configs/simulation.yaml"
    settle_frames: int = -1
    drape_frames: int = 120
    drape_rest_speed: float = 0.001
    workers: int = 0
    executor: str = "local"
    ray_address: str = ""
    outfits: int = 0
    splits: SplitConfig = field(default_factory=SplitConfig)

    def __post_init__(self) -> None:
        """Check names and ranges before any work starts (a build with an unknown motion
        would otherwise run and leave every sequence out)."""
        from data_prep.executor import EXECUTORS
        from data_prep.garments import GARMENT_TYPES
        from data_prep.simulate.fabrics import FABRICS
        from gnngarment.body.anny_model import ANNY_PRESETS
        from gnngarment.body.procedural import MOTION_LIBRARY
        from gnngarment.model.config import MAX_LEVELS

        for key, names, known in (("garment_types", self.garment_types, GARMENT_TYPES),
                                  ("motions", self.motions, MOTION_LIBRARY),
                                  ("fabrics", self.fabrics, FABRICS),
                                  ("body_presets", self.body_presets, ANNY_PRESETS)):
            unknown = [name for name in names if name not in known]
            if unknown or (not names and key != "body_presets"):
                raise ValueError(f"key '{key}': unknown {unknown or 'empty list'}; "
                                 f"known: {', '.join(sorted(known))}")
        if len(self.garment_vertices) != 2 or not (
                300 <= self.garment_vertices[0] <= self.garment_vertices[1]):
            raise ValueError("key 'garment_vertices': expected [low, high] with 300 <= low "
                             f"<= high, got {list(self.garment_vertices)}")
        for key in ("fps", "motion_seconds", "drape_rest_speed", "motion_window_seconds"):
            value = getattr(self, key)
            if not value > 0 or value != value or value == float("inf"):
                raise ValueError(f"key '{key}': must be a finite number > 0, got {value}")
            if value > UPPER_LIMITS.get(key, float("inf")):
                raise ValueError(f"key '{key}': at most {UPPER_LIMITS[key]:g}, got {value:g} "
                                 "(docs/reliability.md, resource limits)")
        if self.levels > MAX_LEVELS:
            raise ValueError(f"key 'levels': the model pools at most {MAX_LEVELS} levels, got "
                             f"{self.levels}")
        for key in ("garments", "bodies", "motions_per_pair", "motion_variants", "body_vertices",
                    "collision_points", "levels", "landmarks", "drape_frames"):
            if getattr(self, key) < 1:
                raise ValueError(f"key '{key}': must be >= 1, got {getattr(self, key)}")
        if self.windows_per_clip < 1 or self.held_out_motions_per_pair < 1:
            key = "windows_per_clip" if self.windows_per_clip < 1 else "held_out_motions_per_pair"
            raise ValueError(f"key '{key}': must be >= 1, got {getattr(self, key)}")
        for key in ("lead_in_seconds", "hold_seconds"):
            value = getattr(self, key)
            if not 0 <= value <= 10:
                raise ValueError(f"key '{key}': must be in [0, 10] seconds, got {value}")
        subjects = set(self.splits.val_subjects) | set(self.splits.test_subjects)
        if set(self.splits.val_subjects) & set(self.splits.test_subjects):
            raise ValueError("key 'splits': a subject cannot be in both val_subjects and "
                             "test_subjects")
        if subjects and not self.motion_files:
            raise ValueError("key 'splits': val_subjects/test_subjects need motion_files")
        for key in ("extra_train_garments", "extra_val_garments", "extra_test_garments",
                    "outfits"):
            if getattr(self, key) < 0:
                raise ValueError(f"key '{key}': must be >= 0, got {getattr(self, key)}")
        if self.motion_variants > self.motions_per_pair:
            raise ValueError(f"key 'motion_variants': {self.motion_variants} variants need at "
                             f"least as many motions per pair, got {self.motions_per_pair}")
        if self.settle_frames < -1:
            raise ValueError(f"key 'settle_frames': must be >= -1, got {self.settle_frames}")
        if self.workers < 0:
            raise ValueError(f"key 'workers': must be >= 0, got {self.workers}")
        if self.executor not in EXECUTORS:
            raise ValueError(f"key 'executor': unknown '{self.executor}'; known: "
                             f"{', '.join(EXECUTORS)}")
        if self.ray_address and self.executor != "ray":
            raise ValueError(f"key 'ray_address': '{self.ray_address}' is only used with "
                             f"executor: ray, not {self.executor}")
