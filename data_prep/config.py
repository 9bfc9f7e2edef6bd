"""Settings of a dataset build (``configs/data/*.yaml``)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class SplitConfig:
    """How many garment designs, bodies and motions each held-out split gets. Held-out
    items never appear in training; validation and test sequences combine a held-out
    design, body and motion (everything unseen at once)."""

    val_garments: int = 1
    test_garments: int = 2
    val_bodies: int = 1
    test_bodies: int = 1
    val_motions: int = 1
    test_motions: int = 1


@dataclass
class DataConfig:
    """A synthetic CLOTH3D-like dataset.

    Attributes:
        output: cache folder (``raw/`` holds the CLOTH3D-format sequences).
        seed: seeds every sampler of the build.
        garment_types: garment types to cycle through.
        garments: garment designs in total (train + held out).
        garment_vertices: [min, max] target vertex count of a garment.
        bodies: body shapes in total; named presets are used first, then samples.
        body_presets: Anny presets to use first.
        motions: procedural motion names (train + held out; held-out ones are the last).
        motion_seconds: length of every motion (s); fps: frames per second.
        motions_per_pair: train motions simulated per (design, body) pair.
        fabrics: fabrics to cycle through (CLOTH3D names).
        body_vertices: ``N_b'`` feature subset size; collision_points: body samples
            stored per frame for the collision loss and rate.
        levels, landmarks: pooling levels and Nyström landmarks of the topology cache.
        simulation: simulation settings file (``configs/simulation.yaml``).
        settle_frames: overrides the simulation file's settle frames (-1 = keep).
        workers: simulation processes (0 = one per core).
        splits: held-out counts.
    """

    output: str = "data/demo"
    seed: int = 0
    garment_types: list[str] = field(default_factory=lambda: [
        "skirt", "dress", "jumpsuit", "tshirt", "trousers", "top"])
    garments: int = 12
    garment_vertices: list[int] = field(default_factory=lambda: [900, 1500])
    bodies: int = 4
    body_presets: list[str] = field(default_factory=list)
    motions: list[str] = field(default_factory=lambda: ["walk", "squat", "arm_raise", "twist",
                                                        "run", "wave"])
    motion_seconds: float = 2.0
    fps: float = 30.0
    motions_per_pair: int = 1
    fabrics: list[str] = field(default_factory=lambda: ["cotton", "silk", "denim", "leather"])
    body_vertices: int = 128
    collision_points: int = 2048
    levels: int = 3
    landmarks: int = 64
    simulation: str = "configs/simulation.yaml"
    settle_frames: int = -1
    workers: int = 0
    splits: SplitConfig = field(default_factory=SplitConfig)
