"""Checks of :func:`data_prep.simulate.simulate_garment`'s inputs (shapes, finiteness,
index ranges), each failure a ``ValueError`` that names the argument and the problem."""

from __future__ import annotations

import dataclasses

import numpy as np


@dataclasses.dataclass
class SimulationInputs:
    """Validated inputs as contiguous float64 / int64 arrays.

    Attributes:
        garment_rest: ``(N, 3)`` [m]; garment_faces ``(F, 3)``.
        body_vertices: ``(T, N_b, 3)`` [m]; body_faces ``(F_b, 3)``.
        fps: frames per second.
        pinned: ``(P,)`` vertex indices (possibly empty).
        pin_targets: ``(T, P, 3)`` [m].
    """

    garment_rest: np.ndarray
    garment_faces: np.ndarray
    body_vertices: np.ndarray
    body_faces: np.ndarray
    fps: float
    pinned: np.ndarray
    pin_targets: np.ndarray


def _points(name: str, value: object, ndim: int, expected: str) -> np.ndarray:
    array = np.asarray(value)
    if array.ndim != ndim or array.shape[-1] != 3:
        raise ValueError(f"{name} must have shape {expected}, got {array.shape}")
    if not np.issubdtype(array.dtype, np.number) or np.issubdtype(array.dtype,
                                                                  np.complexfloating):
        raise ValueError(f"{name} must be real numbers, got dtype {array.dtype}")
    array = np.ascontiguousarray(array, dtype=np.float64)
    if not np.isfinite(array).all():
        raise ValueError(f"{name} contains NaN or inf")
    return array


def _indices(name: str, value: object, shape: str, ndim: int, count: int) -> np.ndarray:
    array = np.asarray(value)
    if array.ndim != ndim or (ndim == 2 and array.shape[1] != 3):
        raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
    if array.size and not np.issubdtype(array.dtype, np.integer):
        raise ValueError(f"{name} must hold integer indices, got dtype {array.dtype}")
    array = np.ascontiguousarray(array, dtype=np.int64)
    if array.size and (array.min() < 0 or array.max() >= count):
        raise ValueError(f"{name} indices must lie in [0, {count}), got "
                         f"[{array.min()}, {array.max()}]")
    return array


def validate_inputs(garment_rest: object, garment_faces: object, body_vertices: object,
                    body_faces: object, fps: object, pinned: object = None,
                    pin_targets: object = None) -> SimulationInputs:
    """Check and normalise the arguments of ``simulate_garment``.

    Raises:
        ValueError: wrong shape or dtype, NaN/inf, out-of-range or repeated index,
            degenerate garment edge, non-positive fps, pin targets without pins or of the
            wrong length; the message names the argument.
    """
    rest = _points("garment_rest", garment_rest, 2, "(N, 3)")
    if len(rest) < 3:
        raise ValueError(f"garment_rest needs at least 3 vertices, got {len(rest)}")
    faces = _indices("garment_faces", garment_faces, "(F, 3)", 2, len(rest))
    if len(faces) == 0:
        raise ValueError("garment_faces is empty")
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    if not (np.linalg.norm(rest[edges[:, 0]] - rest[edges[:, 1]], axis=1) > 1e-9).all():
        raise ValueError("garment_faces has a degenerate face (zero-length rest edge)")
    body = _points("body_vertices", body_vertices, 3, "(T, N_b, 3)")
    if body.shape[0] < 1 or body.shape[1] < 4:
        raise ValueError(f"body_vertices must have T >= 1 frames of N_b >= 4 vertices, got "
                         f"{body.shape}")
    body_faces_ = _indices("body_faces", body_faces, "(F_b, 3)", 2, body.shape[1])
    if len(body_faces_) < 4:
        raise ValueError(f"body_faces must describe a closed mesh, got {len(body_faces_)} "
                         "faces")
    if (isinstance(fps, bool) or not isinstance(fps, (int, float, np.number))
            or not np.isfinite(fps) or fps <= 0):
        raise ValueError(f"fps must be a positive finite number, got {fps!r}")
    pins, targets = _pins(pinned, pin_targets, rest, body.shape[0])
    return SimulationInputs(rest, faces, body, body_faces_, float(fps), pins, targets)


def _pins(pinned: object, pin_targets: object, rest: np.ndarray,
          num_frames: int) -> tuple[np.ndarray, np.ndarray]:
    """Pinned indices ``(P,)`` and their targets ``(T, P, 3)`` (held at the rest
    positions when no targets are given)."""
    if pinned is None:
        if pin_targets is not None:
            raise ValueError("pin_targets given without pinned vertex indices")
        return np.zeros(0, dtype=np.int64), np.zeros((num_frames, 0, 3))
    pins = _indices("pinned", pinned, "(P,)", 1, len(rest))
    if len(np.unique(pins)) != len(pins):
        raise ValueError("pinned contains repeated vertex indices")
    if pin_targets is None:
        return pins, np.broadcast_to(rest[pins], (num_frames, len(pins), 3)).copy()
    targets = _points("pin_targets", pin_targets, 3, "(T, P, 3)")
    if targets.shape[:2] != (num_frames, len(pins)):
        raise ValueError(f"pin_targets must have shape (T, P, 3) = ({num_frames}, "
                         f"{len(pins)}, 3), got {targets.shape}")
    return pins, targets
