"""Dresses: a bodice (sleeved, sleeveless or strapless) over a flared skirt."""

from __future__ import annotations

import dataclasses
from typing import ClassVar

from data_prep.garments.body_frame import BodyFrame
from data_prep.garments.outline import GarmentOutline
from data_prep.garments.parts import (
    NECKLINES,
    bounds,
    hem_cut,
    hem_low,
    styled_upper_parts,
    trunk_stack,
)
from data_prep.garments.shapes import Design
from data_prep.garments.style import Style, choice, number


@dataclasses.dataclass(frozen=True)
class DressStyle(Style):
    """A dress: fitted bodice, skirt flaring from the hips."""

    garment_type: ClassVar[str] = "dress"
    sleeves: str = choice("sleeveless", ("sleeved", "sleeveless", "strapless"),
                          "sleeves, shoulder straps or strapless", weights=(2.0, 2.0, 1.0))
    length: float = number(0.4, 0.1, 0.85, "hem drop below the crotch as a fraction of "
                           "crotch-to-ankle (mini → maxi)")
    flare: float = number(0.3, 0.0, 0.6, "skirt widening in metres per metre below the hips")
    looseness: float = number(0.025, 0.015, 0.05, "ease of the bodice (m)")
    sleeve_length: float = number(0.3, 0.12, 1.0, "sleeved: fraction of shoulder-to-wrist length")
    sleeve_looseness: float = number(0.025, 0.015, 0.05, "sleeved: ease around the arm (m)")
    strap: float = number(0.05, 0.025, 0.1, "sleeveless: shoulder strap width (m)")
    armhole_drop: float = number(0.02, 0.0, 0.06, "sleeveless: armhole depth below the armpit "
                                 "(m)")
    top_edge: float = number(0.04, 0.01, 0.1, "strapless: top edge below the armpits (m)")
    neckline: str = choice("round", NECKLINES, "neckline shape")
    neck_depth: float = number(0.07, 0.02, 0.16, "neckline depth in front (m)")
    back_depth: float = number(0.03, 0.015, 0.08, "neckline depth at the back (m)")
    neck_width: float = number(0.02, 0.0, 0.05, "neckline width beyond the neck, each side (m)")
    front_rise: float = number(0.0, -0.04, 0.1, "hem higher in front than at the back (m)")


def dress_outline(body: BodyFrame, style: DressStyle) -> GarmentOutline:
    m = body.measurements
    z_hem = (m.z_crotch - 0.06) - style.length * (m.z_crotch - 0.06 - (m.z_ankle + 0.06))
    torso = trunk_stack(m, z_hem - 0.1, float(m.shoulder_z.max()) + 0.1, style.looseness,
                        skirt_from=m.z_hip, flare=style.flare, vertices=body.vertices)
    extra, cuts, loops, top = styled_upper_parts(body.vertices, m, torso, style,
                                                 sleeve_flare=0.0)
    solids = [torso, *extra]
    hem = hem_cut(z_hem, torso, front_rise=style.front_rise)
    design = Design(solids=solids, cuts=[hem, *cuts],
                    bounds=bounds(solids, hem_low(z_hem, style.front_rise),
                                  float(m.shoulder_z.max()) + 0.15))
    return GarmentOutline(design=design, loops=loops + 1, top=top)
