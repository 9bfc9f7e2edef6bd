"""Bring a user's garment onto the rest body: from the body it was made on, or by
explicit units/turn/scale/offset; optionally drape it there.

The model animates a garment in the rest body's frame, as worn at rest (DESIGN.md). A
user's file rarely is: :func:`place_garment` applies what they know (the source body
they modelled on, or ``--scale``/``--offset``/``--up-axis``) and says what it did in
one line per step; :func:`drape_on_rest_body` settles it with the reference simulator.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
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
    return drape_outfit_on_rest_body([placed], [faces], body, max_frames, progress)[0]


def drape_outfit_on_rest_body(placed: Sequence[PlacedGarment], faces: Sequence[np.ndarray],
                              body: BodyShapeInputs, max_frames: int = 120,
                              progress: Callable[[int, int], None] | None = None
                              ) -> list[PlacedGarment]:
    """Settle several garments on the still rest body together, in one simulation: what
    ``animate --drape`` does for an outfit. With more than one garment the simulator's
    cloth self-contact is on, so each garment settles on the ones it touches instead of
    through them (about 2× the cost of one scene without it); each garment's top band is
    held as in :func:`drape_on_rest_body`.

    Shapes:
        placed[i].pos ``(N_i, 3)`` and faces[i] ``(F_i, 3)``; the result in that order.

    Raises:
        ValueError: the simulator refused the input; SimulationFailed: every attempt
        failed a quality gate.
    """
    # Imported here: the simulator (warp, Newton) is heavy and only this step needs it.
    from data_prep.simulate import SimulationSettings, drape_garment
    from gnngarment.geometry.boundary import support_band

    if len(placed) != len(faces) or not placed:
        raise ValueError(f"one faces array per garment: {len(placed)} garments, "
                         f"{len(faces)} faces arrays")
    starts = np.cumsum([0] + [len(one.pos) for one in placed])
    scene_pos = np.concatenate([one.pos for one in placed])
    scene_faces = np.concatenate([np.asarray(f, dtype=np.int64) + start
                                  for f, start in zip(faces, starts[:-1], strict=True)])
    # As the dataset builder pins a waist ring: a garment hangs from its top band.
    bands = [support_band(one.pos, f, body.rest_vertices)
             for one, f in zip(placed, faces, strict=True)]
    pinned = np.concatenate([band + start for band, start in zip(bands, starts[:-1],
                                                                   strict=True)])
    settings = SimulationSettings(self_contact=len(placed) > 1)
    result = drape_garment(scene_pos, scene_faces, body.rest_vertices, body.faces,
                           pinned=pinned if len(pinned) else None, settings=settings,
                           max_frames=max_frames, progress=progress)
    state = "settled" if result.settled else f"stopped at the {max_frames}-frame cap"
    if len(placed) > 1:
        state += f" with the {len(placed)} garments of the outfit in one scene"
    draped = []
    for index, one in enumerate(placed):
        pos = result.positions[starts[index]:starts[index + 1]].astype(np.float64)
        moved = float(np.linalg.norm(pos - one.pos, axis=1).mean())
        held = (f", hanging from its top band ({len(bands[index])} vertices held)"
                if len(bands[index]) else "")
        draped.append(PlacedGarment(
            pos=pos, fitted=one.fitted, seconds={**one.seconds, "drape": result.seconds},
            messages=[*one.messages,
                      f"draped on the rest body: {state}{held} after {result.frames} "
                      f"frames, {1000 * moved:.0f} mm mean move ({result.seconds:.1f} s)"]))
    return draped
