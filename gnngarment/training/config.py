"""Training settings (defaults mirror ``configs/train/paper.yaml``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

from gnngarment.model.config import ModelConfig

#: Stages with an entry in ``stages.max_epochs`` (the schedule's order).
TRAINED_STAGES = ("supervised", "physics", "physics_strain")


def _check_at_least(key: str, value: int, low: int, high: int | None = None) -> None:
    if value < low:
        raise ValueError(f"key '{key}': must be >= {low}, got {value}")
    if high is not None and value > high:
        raise ValueError(f"key '{key}': must be <= {high:,}, got {value:,}")


#: Upper bounds of the training sizes (docs/reliability.md "Resource limits"): far above
#: any recipe (the paper's batch is 4 pairs x 16 frames), below what exhausts memory
#: before the first step (``pairs_per_batch: 1e9`` ran).
TRAINING_SIZE_LIMITS = {"seed": 2**32 - 1, "epochs": 100_000, "pairs_per_batch": 256,
                        "frames_per_pair": 256, "threads": 1024, "validate_every": 100_000}


def _check_finite(key: str, value: float, positive: bool = False) -> None:
    """``value`` finite and ``>= 0`` (``> 0`` when ``positive``)."""
    if not math.isfinite(value) or value < 0 or (positive and value == 0):
        raise ValueError(f"key '{key}': must be a finite number {'>' if positive else '>='} 0, "
                         f"got {value}")


@dataclass
class LossWeights:
    """Weights of the loss terms (blueprint Sec. 3.4)."""

    vertex: float = 100.0
    edge: float = 15.0
    normal: float = 50.0
    collision: float = 1.5
    gravity: float = 0.1
    stretch: float = 5.0
    shear: float = 2.0
    #: Not in the blueprint (0 = off): mean squared blend shape (m²), pulling the
    #: corrections towards plain skinning of the template unless the data asks for them.
    blend_shape: float = 0.0


@dataclass
class StageConfig:
    """When to switch stages: a stage ends when its watched metric improved by less than
    ``threshold`` (relative) over the last ``window`` epochs, or after ``max_epochs``.

    Attributes:
        supervised_window, supervised_threshold: stage 1 watches the vertex error
            (blueprint: 50 epochs, 4 %).
        collision_window, collision_threshold: stage 2 watches the collision term
            before adding stretch + shear (blueprint: 20 epochs, 5 %).
        strain_window, strain_threshold: when the final stage ends.
        physics_scale: stage 2 multiplies the vertex and edge weights by this (0.1).
        supervised_collision: not in the blueprint (0 = off): stage 1 also weights the
            collision term by this. Stage 1 is the only stage that trains the skinning
            weights, and they are what puts the raw output inside the body
            (docs/limitations.md).
        max_epochs: per stage, a hard limit (0 = none).
    """

    supervised_window: int = 50
    supervised_threshold: float = 0.04
    collision_window: int = 20
    collision_threshold: float = 0.05
    strain_window: int = 20
    strain_threshold: float = 0.05
    physics_scale: float = 0.1
    supervised_collision: float = 0.0
    max_epochs: list[int] = field(default_factory=lambda: [0, 0, 0])


@dataclass
class TrainingConfig:
    """Everything ``gnngarment train`` needs.

    Attributes:
        data: prepared cache folder.
        output: run folder (checkpoints, TensorBoard logs, metrics).
        model: network settings.
        seed: seeds torch, numpy and the batch order.
        epochs: total epoch limit over all stages.
        pairs_per_batch, frames_per_pair: a batch is ``P`` sequences × ``B`` frames
            (the blueprint's batch of 64 = e.g. 4 × 16).
        learning_rate: Adamax learning rate, decayed by a cosine over ``epochs``.
        collision_margin: ε of the collision term (metres).
        threads: torch intra-op threads (0 = the cores idle when training starts,
            :func:`gnngarment.threads.choose_threads`).
        validate_every: epochs between validation passes.
        deterministic: torch's deterministic algorithms (its scatter/index-add
            reductions otherwise sum in a thread-dependent order): two runs of one
            config and seed give bitwise-equal weights with any thread count
            (docs/reliability.md has the measured cost).
        initial_weights: a model checkpoint whose weights start a new run (fine-tuning,
            e.g. adding ``model.dynamics_modes`` to a trained model); the parts of this
            model it has no weights for (the oscillators) keep their initialisation,
            every other weight must fit. ``null`` (the default) or empty: a fresh
            initialisation (``--set initial_weights=null`` starts a config that names
            weights from scratch). Ignored when a run resumes (its own checkpoint has
            every weight).
    """

    data: str = "data/paper"
    output: str = "runs/paper"
    model: ModelConfig = field(default_factory=ModelConfig)
    losses: LossWeights = field(default_factory=LossWeights)
    stages: StageConfig = field(default_factory=StageConfig)
    seed: int = 0
    epochs: int = 200
    pairs_per_batch: int = 4
    frames_per_pair: int = 16
    learning_rate: float = 3e-3
    collision_margin: float = 0.004
    threads: int = 0
    validate_every: int = 1
    deterministic: bool = True
    initial_weights: str | None = None

    def __post_init__(self) -> None:
        """Check ranges before any work starts (``epochs: 0`` would report a checkpoint
        that is never written, ``learning_rate: nan`` would train to NaN). Model
        settings are checked by :meth:`ModelConfig.validate`.

        Raises:
            ValueError: naming the key, e.g. ``key 'stages.max_epochs'``.
        """
        for key, low in (("seed", 0), ("epochs", 1), ("pairs_per_batch", 1),
                         ("frames_per_pair", 1), ("threads", 0), ("validate_every", 1)):
            _check_at_least(key, getattr(self, key), low, TRAINING_SIZE_LIMITS[key])
        _check_finite("learning_rate", self.learning_rate, positive=True)
        _check_finite("collision_margin", self.collision_margin)
        for item in fields(self.losses):
            _check_finite(f"losses.{item.name}", getattr(self.losses, item.name))
        stages = self.stages
        for name in ("supervised", "collision", "strain"):
            _check_at_least(f"stages.{name}_window", getattr(stages, f"{name}_window"), 1)
            _check_finite(f"stages.{name}_threshold", getattr(stages, f"{name}_threshold"))
        _check_finite("stages.physics_scale", stages.physics_scale)
        _check_finite("stages.supervised_collision", stages.supervised_collision)
        if len(stages.max_epochs) != len(TRAINED_STAGES) or min(stages.max_epochs) < 0:
            raise ValueError(f"key 'stages.max_epochs': expected {len(TRAINED_STAGES)} epoch "
                             f"limits >= 0 ({', '.join(TRAINED_STAGES)}; 0 = none), got "
                             f"{list(stages.max_epochs)}")
