"""Jumpsuits: trouser legs joined to a bodice (sleeved, sleeveless or strapless)."""

from __future__ import annotations

import dataclasses
from typing import ClassVar

from data_prep.garments.body_frame import BodyFrame
from data_prep.garments.outline import GarmentOutline
from data_prep.garments.parts import (
    LEG_BLEND,
    NECKLINES,
    SEAT_BLEND,
    bounds,
    hem_cut,
    styled_upper_parts,
    trunk_stack,
)
from data_prep.garments.shapes import Design, Group
from data_prep.garments.style import Style, choice, number
from data_prep.garments.trousers import leg_parts


@dataclasses.dataclass(frozen=True)
class JumpsuitStyle(Style):
    """A jumpsuit / playsuit: one piece from the shoulders down both legs."""

    garment_type: ClassVar[str] = "jumpsuit"
    sleeves: str = choice("sleeveless", ("sleeved", "sleeveless", "strapless"),
                          "sleeves, shoulder straps or strapless", weights=(2.0, 2.0, 1.0))
    length: float = number(0.8, 0.15, 1.0, "leg length: 0 = at the crotch, 1 = 3 cm above the "
                           "ankle")
    looseness: float = number(0.03, 0.015, 0.06, "ease around the torso (m)")
    leg_looseness: float = number(0.03, 0.012, 0.06, "ease around the legs (m)")
    flare: float = number(0.05, 0.0, 0.25, "leg widening in metres per metre of drop")
    flare_from: float = number(0.5, 0.0, 1.0, "where the widening starts: 0 = crotch, 1 = knee")
    crotch_drop: float = number(0.03, 0.0, 0.06, "crotch seam below the body's crotch (m)")
    sleeve_length: float = number(0.3, 0.12, 1.0, "sleeved: fraction of shoulder-to-wrist length")
    sleeve_looseness: float = number(0.025, 0.015, 0.05, "sleeved: ease around the arm (m)")
    strap: float = number(0.05, 0.025, 0.1, "sleeveless: shoulder strap width (m)")
    armhole_drop: float = number(0.02, 0.0, 0.06, "sleeveless: armhole depth below the armpit "
                                 "(m)")
    top_edge: float = number(0.04, 0.01, 0.1, "strapless: top edge below the armpits (m)")
    neckline: str = choice("round", NECKLINES, "neckline shape")
    neck_depth: float = number(0.07, 0.02, 0.16, "neckline depth in front (m)")
    back_depth: float = number(0.02, 0.015, 0.06, "neckline depth at the back (m)")
    neck_width: float = number(0.02, 0.0, 0.05, "neckline width beyond the neck, each side (m)")


def jumpsuit_outline(body: BodyFrame, style: JumpsuitStyle) -> GarmentOutline:
    m = body.measurements
    z_crotch = m.z_crotch - style.crotch_drop
    torso = trunk_stack(m, z_crotch - 0.05, float(m.shoulder_z.max()) + 0.1, style.looseness,
                        bottom=z_crotch)
    legs, z_hem = leg_parts(m, torso, style.length, style.leg_looseness, style.flare,
                            style.flare_from)
    extra, cuts, loops, top = styled_upper_parts(body.vertices, m, torso, style,
                                                 sleeve_flare=0.0)
    solids = [torso, Group(tuple(legs), blend=LEG_BLEND), *extra]
    design = Design(solids=solids, blend=SEAT_BLEND,
                    cuts=[hem_cut(z_hem, legs[0], name="leg"), *cuts],
                    bounds=bounds(solids, z_hem, float(m.shoulder_z.max()) + 0.15))
    return GarmentOutline(design=design, loops=loops + 2, top=top)
