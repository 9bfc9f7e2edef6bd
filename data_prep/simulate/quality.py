"""Per-frame quality of a simulated sequence and the gates it must pass to become data."""

from __future__ import annotations

import dataclasses

import numpy as np


def unique_edges(faces: np.ndarray) -> np.ndarray:
    """Undirected edges of a triangle mesh.

    Args:
        faces: ``(F, 3)`` int.

    Returns:
        ``(E, 2)`` int64, each edge once with ``i < j``.
    """
    faces = np.asarray(faces, dtype=np.int64)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return np.unique(np.sort(edges, axis=1), axis=0)


def max_edge_stretch(pos: np.ndarray, edges: np.ndarray, rest_length: np.ndarray) -> float:
    """Largest ratio current / rest length over ``edges`` (1 = no stretch).

    Args:
        pos: ``(N, 3)`` [m]; edges ``(E, 2)``; rest_length ``(E,)`` [m], > 0.
    """
    length = np.linalg.norm(pos[edges[:, 0]] - pos[edges[:, 1]], axis=1)
    return float(np.max(length / rest_length)) if len(edges) else 1.0


@dataclasses.dataclass
class QualityReport:
    """Quality of one simulated sequence, frame by frame.

    Attributes:
        max_stretch: ``(T,)`` largest edge length / rest length per frame.
        inside_fraction: ``(T,)`` fraction of unpinned vertices inside the body.
        finite: ``(T,)`` bool, all positions of the frame finite.
        frames_simulated: frames actually simulated (an attempt stops at its first failing
            frame, so later entries are NaN / False).
        failure: why the sequence failed (first failing frame), or ``""``.
        substeps: substeps per frame of the attempt this report describes.
    """

    max_stretch: np.ndarray
    inside_fraction: np.ndarray
    finite: np.ndarray
    frames_simulated: int
    failure: str = ""
    substeps: int = 0

    @classmethod
    def empty(cls, num_frames: int, substeps: int) -> QualityReport:
        """A report for ``num_frames`` frames with nothing measured yet."""
        return cls(max_stretch=np.full(num_frames, np.nan),
                   inside_fraction=np.full(num_frames, np.nan),
                   finite=np.zeros(num_frames, dtype=bool), frames_simulated=0,
                   substeps=substeps)

    @property
    def ok(self) -> bool:
        """True when every frame was simulated and passed the gates."""
        return not self.failure and self.frames_simulated == len(self.finite)

    def summary(self) -> str:
        """One line for logs: worst stretch and inside fraction, and the failure."""
        measured = slice(0, self.frames_simulated)
        stretch = np.nanmax(self.max_stretch[measured]) if self.frames_simulated else np.nan
        inside = np.nanmax(self.inside_fraction[measured]) if self.frames_simulated else np.nan
        status = "ok" if self.ok else f"FAILED: {self.failure}"
        return (f"{self.frames_simulated}/{len(self.finite)} frames at {self.substeps} "
                f"substeps, max stretch {stretch:.3f}, max inside {100 * inside:.2f}% "
                f"— {status}")


def gate_failure(frame: int, finite: bool, stretch: float, inside: float,
                 max_stretch: float, max_inside: float) -> str:
    """The reason frame ``frame`` fails the gates, or ``""`` when it passes."""
    if not finite:
        return f"frame {frame}: non-finite positions (NaN/inf)"
    if not stretch <= max_stretch:
        return f"frame {frame}: max edge stretch {stretch:.3f} > {max_stretch:.3f}"
    if not inside <= max_inside:
        return (f"frame {frame}: {100 * inside:.2f}% of vertices inside the body > "
                f"{100 * max_inside:.2f}%")
    return ""
