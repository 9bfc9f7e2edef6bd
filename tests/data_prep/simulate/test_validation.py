"""Input validation of `simulate_garment` (no Newton run: these fail before any kernel is
compiled)."""

from __future__ import annotations

import numpy as np
import pytest

from data_prep.simulate import simulate_garment
from tests.meshes import grid


def _valid_inputs() -> dict:
    pos, faces = grid(4, 4, spacing=0.05)
    body = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]) - 3.0
    body_faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return dict(garment_rest=pos, garment_faces=faces, body_vertices=np.stack([body] * 3),
                body_faces=body_faces, fps=30.0)


def _with(**changes: object) -> dict:
    inputs = _valid_inputs()
    inputs.update(changes)
    return inputs


def _nan_rest() -> np.ndarray:
    pos = _valid_inputs()["garment_rest"].copy()
    pos[3, 1] = np.nan
    return pos


def _degenerate_rest() -> np.ndarray:
    pos = _valid_inputs()["garment_rest"].copy()
    pos[1] = pos[0]
    return pos


@pytest.mark.parametrize("changes,message", [
    (dict(garment_rest=np.zeros((16, 2))), r"garment_rest must have shape \(N, 3\)"),
    (dict(garment_rest=_nan_rest()), "garment_rest contains NaN"),
    (dict(garment_faces=np.zeros((5, 4), dtype=int)), r"garment_faces must have shape"),
    (dict(garment_faces=np.array([[0, 1, 16]])), r"garment_faces indices must lie in \[0, 16\)"),
    (dict(garment_faces=np.array([[0.0, 1.0, 2.0]])), "garment_faces must hold integer"),
    (dict(garment_rest=_degenerate_rest()), "degenerate face"),
    (dict(body_vertices=np.zeros((4, 3))), r"body_vertices must have shape \(T, N_b, 3\)"),
    (dict(body_vertices=np.full((2, 4, 3), np.inf)), "body_vertices contains NaN or inf"),
    (dict(body_faces=np.array([[0, 1, 9]] * 4)), r"body_faces indices must lie in \[0, 4\)"),
    (dict(fps=0.0), "fps must be a positive finite number"),
    (dict(fps=float("nan")), "fps must be a positive finite number"),
    (dict(pinned=np.array([0, 0])), "pinned contains repeated"),
    (dict(pinned=np.array([99])), r"pinned indices must lie in \[0, 16\)"),
    (dict(pin_targets=np.zeros((3, 1, 3))), "pin_targets given without pinned"),
    (dict(pinned=np.array([0, 1]), pin_targets=np.zeros((2, 2, 3))),
     r"pin_targets must have shape \(T, P, 3\) = \(3, 2, 3\)"),
    (dict(fabric="tweed"), "unknown fabric"),
])
def test_bad_inputs_raise_value_errors_naming_the_problem(changes: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        simulate_garment(**_with(**changes))
