"""``simulate_garment``: the reference cloth simulation as a pure function of arrays.

The garment starts on the rest body (frame 0), drapes for ``settle_frames`` frames with the
body held still, then follows the motion. Every output frame is checked (finite, edge
stretch, vertices inside the body); a failing sequence is re-run with more substeps and,
if it still fails, raises :class:`SimulationFailed` — it must never become data.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from data_prep.simulate.fabrics import FabricPreset, resolve_fabric
from data_prep.simulate.inside import signed_distance_warp
from data_prep.simulate.quality import QualityReport, gate_failure, max_edge_stretch, unique_edges
from data_prep.simulate.settings import SimulationSettings
from data_prep.simulate.validation import SimulationInputs, validate_inputs

if TYPE_CHECKING:  # the scene imports Warp/Newton lazily; only its type is needed here
    from data_prep.simulate.scene import ClothScene

#: ``progress(frames_done, frames_total)``, called after every simulated frame (settling
#: frames included) of every attempt.
ProgressCallback = Callable[[int, int], None]


@dataclasses.dataclass
class SimulationResult:
    """A simulated sequence that passed the quality gates.

    Attributes:
        positions: ``(T, N, 3)`` float32 garment vertices [m], one per animation frame
            (frame 0 is the settled drape on the first pose).
        quality: per-frame quality of the accepted attempt.
        substeps: substeps per frame of the accepted attempt.
        attempts: number of attempts made (1 = no retry).
        seconds_per_frame: wall time per simulated frame of the accepted attempt, its
            first frame (which compiles the kernels on an empty Warp cache) left out [s].
        cpu_seconds_per_frame: the same in CPU time of this process (robust to other
            processes sharing the cores) [s].
        setup_seconds: model construction plus the first simulated frame [s].
        fabric: the material used.
    """

    positions: np.ndarray
    quality: QualityReport
    substeps: int
    attempts: int
    seconds_per_frame: float
    cpu_seconds_per_frame: float
    setup_seconds: float
    fabric: FabricPreset


class SimulationFailed(RuntimeError):  # noqa: N818 - the name the dataset builder catches
    """Every attempt failed a quality gate; the sequence must be left out of the data.

    Attributes:
        report: quality of the last attempt (``report.failure`` says why).
        reports: quality of every attempt, in order.
    """

    def __init__(self, reports: list[QualityReport]) -> None:
        self.reports = reports
        self.report = reports[-1]
        lines = "; ".join(f"attempt {i + 1}: {r.summary()}" for i, r in enumerate(reports))
        super().__init__(f"simulation failed after {len(reports)} attempt(s): {lines}")


def simulate_garment(garment_rest: np.ndarray, garment_faces: np.ndarray,
                     body_vertices: np.ndarray, body_faces: np.ndarray, fps: float,
                     fabric: str | FabricPreset = "cotton", pinned: np.ndarray | None = None,
                     pin_targets: np.ndarray | None = None,
                     settings: SimulationSettings | None = None,
                     progress: ProgressCallback | None = None) -> SimulationResult:
    """Simulate a garment on an animated body with NVIDIA Newton's VBD cloth solver.

    Args:
        garment_rest: ``(N, 3)`` rest garment on the rest body [m], Z-up.
        garment_faces: ``(F, 3)`` int triangles.
        body_vertices: ``(T, N_b, 3)`` posed body per animation frame [m]; frame 0 is the
            rest/first pose. A closed mesh with outward winding.
        body_faces: ``(F_b, 3)`` int.
        fps: animation frame rate [1/s].
        fabric: preset name (cotton, silk, denim, leather) or a :class:`FabricPreset`.
        pinned: ``(P,)`` vertex indices moved kinematically (e.g. a waist ring).
        pin_targets: ``(T, P, 3)`` their positions per frame [m]; default: held at rest.
        settings: solver, contact, retry and gate settings (default
            :class:`SimulationSettings`).
        progress: ``progress(frames_done, frames_total)`` after every simulated frame.

    Returns:
        :class:`SimulationResult` with ``positions`` ``(T, N, 3)`` float32.

    Raises:
        ValueError: malformed input (the message names the argument) or unknown fabric.
        SimulationFailed: every attempt (at most ``1 + settings.max_retries``; fewer when
            ``settings.retry_only_if_progress`` and a retry got no further) failed a gate.
        ImportError: Newton / Warp missing.
    """
    settings = settings if settings is not None else SimulationSettings()
    preset = resolve_fabric(fabric)
    inputs = validate_inputs(garment_rest, garment_faces, body_vertices, body_faces, fps,
                             pinned, pin_targets)
    return with_retries(lambda substeps: _attempt(inputs, preset, settings, substeps,
                                                  progress), settings)


def with_retries(attempt: Callable[[int], tuple[Any, QualityReport]],
                 settings: SimulationSettings) -> Any:
    """Run ``attempt(substeps)`` until it returns a result (not ``None``), with
    ``retry_substep_factor`` times more substeps each retry, at most
    ``1 + max_retries`` times; sets the result's ``attempts``.

    Raises:
        SimulationFailed: every attempt failed a gate (or a retry got no further).
    """
    reports: list[QualityReport] = []
    substeps = settings.substeps
    for number in range(settings.max_retries + 1):
        result, report = attempt(substeps)
        reports.append(report)
        if result is not None:
            result.attempts = number + 1
            return result
        if (settings.retry_only_if_progress and number > 0
                and report.frames_simulated <= reports[-2].frames_simulated):
            break  # more substeps did not get further: a third try would not either
        substeps *= settings.retry_substep_factor
    raise SimulationFailed(reports)


def _schedule(settle_frames: int, num_frames: int) -> list[tuple[int, int, int | None]]:
    """The simulated frames of one attempt: ``(body frame at start, body frame at end,
    output frame recorded after it or None)``. Settling holds the body at frame 0; its last
    frame gives output frame 0 (without settling, output frame 0 is the rest shape)."""
    settle = [(0, 0, 0 if k == settle_frames - 1 else None) for k in range(settle_frames)]
    return settle + [(frame - 1, frame, frame) for frame in range(1, num_frames)]


def _attempt(inputs: SimulationInputs, fabric: FabricPreset, settings: SimulationSettings,
             substeps: int, progress: ProgressCallback | None,
             ) -> tuple[SimulationResult | None, QualityReport]:
    """One run at ``substeps``; stops at the first frame that fails a gate."""
    from data_prep.simulate.scene import ClothScene

    start = time.perf_counter()
    body, pins, rest = inputs.body_vertices, inputs.pin_targets, inputs.garment_rest
    scene = ClothScene(rest, inputs.garment_faces, body[0], inputs.body_faces, inputs.pinned,
                       fabric, settings, substeps, inputs.fps)
    gauge = _Gauge(rest, inputs.garment_faces, inputs.pinned, settings)
    report = QualityReport.empty(len(body), substeps)
    positions = np.empty((len(body), len(rest), 3), dtype=np.float32)
    schedule = _schedule(settings.settle_frames, len(body))
    if settings.settle_frames == 0 and gauge.record(scene, 0, positions, report):
        return None, report
    timings: list[tuple[float, float]] = []  # (wall, cpu) per simulated frame
    for step, (previous, frame, output) in enumerate(schedule, start=1):
        tic, cpu_tic = time.perf_counter(), time.process_time()
        scene.advance(body[previous], body[frame], pins[previous], pins[frame])
        timings.append((time.perf_counter() - tic, time.process_time() - cpu_tic))
        if step == 1:
            setup = time.perf_counter() - start
        if progress is not None:
            progress(step, len(schedule))
        if output is not None and gauge.record(scene, output, positions, report):
            return None, report
    # The first frame compiles the kernels on an empty Warp cache: leave it out.
    timed = np.array(timings[1:] or timings or [(0.0, 0.0)])
    result = SimulationResult(positions=positions, quality=report, substeps=substeps,
                              attempts=1, seconds_per_frame=float(timed[:, 0].mean()),
                              cpu_seconds_per_frame=float(timed[:, 1].mean()),
                              setup_seconds=setup if timings else time.perf_counter() - start,
                              fabric=fabric)
    return result, report


class _Gauge:
    """Measures output frames into a :class:`QualityReport` and applies the gates."""

    def __init__(self, rest: np.ndarray, faces: np.ndarray, pinned: np.ndarray,
                 settings: SimulationSettings) -> None:
        self.edges = unique_edges(faces)
        self.rest_length = np.linalg.norm(rest[self.edges[:, 0]] - rest[self.edges[:, 1]],
                                          axis=1)
        # Pinned vertices go where the caller puts them: they do not count as inside.
        self.free = np.setdiff1d(np.arange(len(rest)), pinned)
        self.settings = settings

    def record(self, scene: ClothScene, frame: int, positions: np.ndarray,
               report: QualityReport) -> bool:
        """Store the scene's cloth as output ``frame`` and measure it; True when it fails
        a gate (``report.failure`` then says why)."""
        pos = positions[frame] = scene.positions()
        finite = bool(np.isfinite(pos).all())
        report.finite[frame] = finite
        if finite:
            report.max_stretch[frame] = max_edge_stretch(pos, self.edges, self.rest_length)
            # The collider's Warp mesh holds this frame's body pose (refit on the last
            # substep), so the inside test needs no mesh of its own.
            depth = signed_distance_warp(scene.body_mesh.mesh, pos[self.free])
            inside = depth < -self.settings.inside_tolerance
            report.inside_fraction[frame] = float(inside.mean()) if len(self.free) else 0.0
        report.frames_simulated = frame + 1
        report.failure = gate_failure(frame, finite, float(report.max_stretch[frame]),
                                      float(report.inside_fraction[frame]),
                                      self.settings.max_edge_stretch,
                                      self.settings.max_inside_fraction)
        return bool(report.failure)
