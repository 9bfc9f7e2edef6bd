"""Bring a user's garment onto the rest body: from the body it was made on, or by
explicit units/turn/scale/offset; optionally drape it there.

The model animates a garment in the rest body's frame, as worn at rest (DESIGN.md). A
user's file rarely is: :func:`place_garment` applies what they know (the source body
they modelled on, or ``--scale``/``--offset``/``--up-axis``) and says what it did in
one line per step; :func:`drape_on_rest_body` settles it with the reference simulator.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from gnngarment.data.body_inputs import BodyShapeInputs
from gnngarment.geometry.body_fitting import FittedGarment, fit_garment
from gnngarment.inference.checks import fix_placement


@dataclass
class PlacedGarment:
    """A garment in the rest body's frame.

    Attributes:
        pos: ``(N, 3)`` metres, Z up, on the rest body.
        messages: what was applied, one line each.
        fitted: the body fit, when a source body was given.
        seconds: wall time of each step that ran (``fit``, ``drape``).
    """

    pos: np.ndarray
    messages: list[str] = field(default_factory=list)
    fitted: FittedGarment | None = None
    seconds: dict[str, float] = field(default_factory=dict)


def place_garment(pos: np.ndarray, faces: np.ndarray, body: BodyShapeInputs,
                  units: str = "auto", up_axis: str = "z", scale: float | None = None,
                  offset: np.ndarray | None = None,
                  source_body: tuple[np.ndarray, np.ndarray] | None = None) -> PlacedGarment:
    """The garment on the rest body.

    With ``source_body`` (the body the garment was modelled on: any topology, units,
    axis-aligned orientation, T-pose) the garment is carried over by
    :func:`~gnngarment.geometry.body_fitting.fit_garment`, which finds units, up axis and
    position itself; the explicit options must then be left at their defaults. Without
    it, :func:`~gnngarment.inference.checks.fix_placement` applies them.

    Shapes:
        pos ``(N, 3)`` as in the file, faces ``(F, 3)``; source_body ``((N_s, 3),
        (F_s, 3))``.

    Raises:
        ValueError: conflicting or invalid options (the message names the option).
    """
    if source_body is not None:
        given = [name for name, changed in (
            ("--fix-units", units != "auto"), ("--up-axis", up_axis != "z"),
            ("--scale", scale is not None), ("--offset", offset is not None)) if changed]
        if given:
            raise ValueError(f"with --source-body the fit finds units, up axis and position "
                             f"itself; leave out {', '.join(given)}")
        started = time.perf_counter()
        fitted = fit_garment(pos, faces, source_body[0], source_body[1], body.rest_vertices,
                             body.faces)
        seconds = time.perf_counter() - started
        return PlacedGarment(pos=fitted.pos, fitted=fitted, seconds={"fit": seconds}, messages=[
            f"fitted from the source body: {fitted.alignment.describe()}; registered to "
            f"{1000 * fitted.registration_error:.1f} mm of the rest body ({seconds:.1f} s)"])
    placed, message = fix_placement(pos, units=units, up_axis=up_axis,
                                    body_vertices=body.rest_vertices, body_faces=body.faces,
                                    scale=scale, offset=offset)
    return PlacedGarment(pos=placed, messages=[message])


def drape_on_rest_body(placed: PlacedGarment, faces: np.ndarray, body: BodyShapeInputs,
                       max_frames: int = 120,
                       progress: Callable[[int, int], None] | None = None) -> PlacedGarment:
    """Settle the garment on the still rest body with the reference simulator (Newton
    VBD, the dataset builder's drape): what ``animate --drape`` does for a garment that
    is not yet at rest. The garment's highest boundary loop, when it goes around the
    body (:func:`~gnngarment.geometry.boundary.support_band`), is held in place.

    Raises:
        ValueError: the simulator refused the input; SimulationFailed: every attempt
        failed a quality gate.
    """
    # Imported here: the simulator (warp, Newton) is heavy and only this step needs it.
    from data_prep.simulate import drape_garment
    from gnngarment.geometry.boundary import support_band

    # As the dataset builder pins a waist ring: a garment hangs from its top band.
    band = support_band(placed.pos, faces, body.rest_vertices)
    result = drape_garment(placed.pos, faces, body.rest_vertices, body.faces,
                           pinned=band if len(band) else None, max_frames=max_frames,
                           progress=progress)
    state = "settled" if result.settled else f"stopped at the {max_frames}-frame cap"
    if len(band):
        state += f", hanging from its top band ({len(band)} vertices held)"
    return PlacedGarment(
        pos=result.positions.astype(np.float64), fitted=placed.fitted,
        seconds={**placed.seconds, "drape": result.seconds},
        messages=[*placed.messages,
                  f"draped on the rest body: {state} after {result.frames} frames, "
                  f"{1000 * result.mean_displacement:.0f} mm mean move "
                  f"({result.seconds:.1f} s)"])
