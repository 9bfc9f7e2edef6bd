"""Settings of the reference cloth simulation (defaults mirrored in
``configs/simulation.yaml``)."""

from __future__ import annotations

import dataclasses
from pathlib import Path


@dataclasses.dataclass
class SimulationSettings:
    """Solver resolution, contact model, retry policy and quality gates.

    Attributes:
        substeps: solver steps per animation frame (dt = 1 / (fps · substeps)).
        iterations: VBD iterations per substep; residual stretch falls with more.
        settle_frames: frames simulated with the body (and pins) held at frame 0 before
            the motion starts, so the garment drapes under gravity first.
        particle_radius: collision thickness of the cloth [m]: vertices rest this far
            off the body surface.
        contact_gap: extra detection distance [m] beyond ``particle_radius`` within which
            body contacts are generated (Newton's ``soft_contact_gap``).
        contact_stiffness: body–cloth penalty stiffness [N/m]. It must dominate the
            membrane stiffness (~10⁴–10⁵ N/m): at 10⁴ a body moving at ~1 m/s pushed
            cotton 2 cm into itself; 3·10⁵ keeps every preset outside, and stiffer
            contact makes friction crumple the cloth (docs/simulation.md).
        contact_damping: body–cloth normal damping [N·s/m] (approach only).
        friction_smoothing: slip speed [m/s] below which Coulomb friction is a linear
            ramp instead of a step (Newton's ``friction_epsilon``).
        self_contact: cloth self-collision (≈2× slower; off for single-layer garments).
        self_contact_distance: self-contact interaction distance [m].
        gravity: magnitude of the gravitational acceleration along −Z [m/s²].
        max_retries: re-runs of a failed sequence, each with ``retry_substep_factor``
            times more substeps than the previous attempt.
        retry_substep_factor: substep multiplier between attempts.
        retry_only_if_progress: give up early when a retry fails at the same frame as
            the attempt before it (or earlier): more substeps did not help, so the
            failure is in the motion or garment, not in the time step (measured on the
            demo set: tight garments in deep squats fail at the same frame with
            10, 20 and 40 substeps; the two extra attempts cost 6× the first).
        max_edge_stretch: quality gate: the largest edge length / rest length allowed
            in any frame.
        max_inside_fraction: quality gate: the largest fraction of (unpinned) garment
            vertices allowed inside the body in any frame.
        inside_tolerance: a vertex counts as inside when it lies deeper than this below
            the body surface [m] (0: any depth).
    """

    substeps: int = 10
    iterations: int = 5
    settle_frames: int = 15
    particle_radius: float = 0.005
    contact_gap: float = 0.01
    contact_stiffness: float = 3.0e5
    contact_damping: float = 1.0
    friction_smoothing: float = 0.01
    self_contact: bool = False
    self_contact_distance: float = 0.004
    gravity: float = 9.81
    max_retries: int = 2
    retry_substep_factor: int = 2
    retry_only_if_progress: bool = True
    max_edge_stretch: float = 1.5
    max_inside_fraction: float = 0.02
    inside_tolerance: float = 0.0

    def __post_init__(self) -> None:
        positive_ints = ("substeps", "iterations", "retry_substep_factor")
        for name in positive_ints:
            if getattr(self, name) < 1:
                raise ValueError(f"simulation setting {name} must be >= 1, got "
                                 f"{getattr(self, name)}")
        for name in ("settle_frames", "max_retries"):
            if getattr(self, name) < 0:
                raise ValueError(f"simulation setting {name} must be >= 0, got "
                                 f"{getattr(self, name)}")
        for name in ("particle_radius", "contact_stiffness", "max_edge_stretch"):
            if not getattr(self, name) > 0:
                raise ValueError(f"simulation setting {name} must be > 0, got "
                                 f"{getattr(self, name)}")
        for name in ("contact_gap", "contact_damping", "friction_smoothing",
                     "self_contact_distance", "gravity",
                     "inside_tolerance"):
            if not getattr(self, name) >= 0:
                raise ValueError(f"simulation setting {name} must be >= 0, got "
                                 f"{getattr(self, name)}")
        if not 0 <= self.max_inside_fraction <= 1:
            raise ValueError("simulation setting max_inside_fraction must lie in [0, 1], "
                             f"got {self.max_inside_fraction}")


def load_simulation_settings(path: str | Path | None = None) -> SimulationSettings:
    """``path`` (e.g. ``configs/simulation.yaml``) merged strictly onto
    :class:`SimulationSettings`; the dataclass defaults when ``path`` is None.

    Raises:
        gnngarment.config.ConfigError: missing file, unknown key, wrong type or value
            out of range (the message names the file and the key).
    """
    if path is None:
        return SimulationSettings()
    from gnngarment.config import ConfigError, load_config

    try:
        return load_config(path, SimulationSettings)
    except ConfigError:
        raise
    except ValueError as error:  # a range check of __post_init__
        raise ConfigError(f"{path}: {error}") from error
