"""Trousers and shorts: a hip tube splitting into two leg tubes at the crotch."""

from __future__ import annotations

import dataclasses
from typing import ClassVar

import numpy as np

from data_prep.garments.body_frame import BodyFrame
from data_prep.garments.errors import PatternError
from data_prep.garments.measurements import BodyMeasurements
from data_prep.garments.outline import GarmentOutline
from data_prep.garments.parts import (
    LEG_BLEND,
    SEAT_BLEND,
    bounds,
    hem_cut,
    leg_stacks,
    trunk_stack,
    waist_cut,
)
from data_prep.garments.shapes import Design, Group, Stack
from data_prep.garments.style import Style, number


@dataclasses.dataclass(frozen=True)
class TrousersStyle(Style):
    """Trousers (shorts to full length; slim, straight, bootcut or wide)."""

    garment_type: ClassVar[str] = "trousers"
    waist_height: float = number(0.5, 0.0, 1.0, "waistband height: 0 = hip joints, 1 = natural "
                                 "waist")
    length: float = number(0.8, 0.15, 1.0, "leg length: 0 = at the crotch, 1 = 3 cm above the "
                           "ankle")
    looseness: float = number(0.02, 0.01, 0.045, "ease at the waist and hips (m)")
    leg_looseness: float = number(0.025, 0.012, 0.06, "ease around the legs (m)")
    flare: float = number(0.05, 0.0, 0.25, "leg widening in metres per metre of drop")
    flare_from: float = number(0.5, 0.0, 1.0, "where the widening starts: 0 = crotch, 1 = knee")
    crotch_drop: float = number(0.02, 0.0, 0.06, "crotch seam below the body's crotch (m)")


def leg_parts(m: BodyMeasurements, hips: Stack, length: float, leg_looseness: float,
              flare: float, flare_from: float) -> tuple[list[Stack], float]:
    """Both legs' solids, reaching up into the ``hips`` solid, and the hem height: at
    ``length`` 0 4 cm below the crotch, at 1 3 cm above the ankle, but raised to where
    the legs are apart, so each leg keeps its own opening.

    Near the crotch a leg's measured section includes part of the seat; there the leg
    is trimmed to stay inside the hips (the seat would otherwise bulge out), so the two
    solids overlap smoothly instead of meeting at a groove or a shelf.

    Raises:
        PatternError: if the legs are never apart above the ankles.
    """
    top_of_hem = m.z_crotch - 0.04
    z_hem = top_of_hem - length * (top_of_hem - (m.z_ankle + 0.03))
    start = m.z_crotch - flare_from * (m.z_crotch - m.z_knee)
    raw, z_apart = leg_stacks(m, leg_looseness, flare, start, top=m.z_crotch + 0.06)
    z_hem = min(z_hem, z_apart - 0.03)
    if z_hem < m.z_ankle:
        raise PatternError("the trouser legs never separate")
    legs = []
    for sign, leg in zip((1.0, -1.0), raw, strict=True):
        z = np.concatenate([leg.z, m.z_crotch + np.arange(0.01, 0.07, 0.01)])
        cx, cy, a, bf, bb, p = leg._profile(z)
        hcx, hcy, ha, hbf, hbb, _ = hips._profile(z)
        weight = np.clip((z - (m.z_crotch - 0.1)) / 0.06, 0.0, 1.0)
        inner = cx - sign * a
        outer = cx + sign * a
        allowed = hcx + sign * (ha - 0.01)
        outer = np.where(sign * (outer - allowed) > 0, outer + weight * (allowed - outer), outer)
        front = np.maximum(cy - bf, cy - bf + weight * ((hcy - hbf + 0.01) - (cy - bf)))
        back = np.minimum(cy + bb, cy + bb + weight * ((hcy + hbb - 0.01) - (cy + bb)))
        legs.append(Stack(z=z, cx=(inner + outer) / 2, cy=cy, a=np.abs(outer - inner) / 2,
                          bf=np.maximum(cy - front, 0.02), bb=np.maximum(back - cy, 0.02), p=p,
                          top_x=leg.top_x, top_z=leg.top_z))
    return legs, z_hem


def trousers_outline(body: BodyFrame, style: TrousersStyle) -> GarmentOutline:
    m = body.measurements
    z_waist = m.z_hip + style.waist_height * (m.z_waist - m.z_hip)
    z_crotch = m.z_crotch - style.crotch_drop
    hips = trunk_stack(m, z_crotch - 0.05, z_waist + 0.1, style.looseness, cap=False,
                       bottom=z_crotch)
    legs, z_hem = leg_parts(m, hips, style.length, style.leg_looseness, style.flare,
                            style.flare_from)
    solids = [hips, Group(tuple(legs), blend=LEG_BLEND)]
    design = Design(solids=solids, blend=SEAT_BLEND,
                    cuts=[waist_cut(z_waist), hem_cut(z_hem, legs[0], name="leg")],
                    bounds=bounds(solids, z_hem, z_waist + 0.03))
    return GarmentOutline(design=design, loops=3, top="waist")
