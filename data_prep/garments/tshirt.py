"""T-shirts: a torso tube with two sleeve tubes, joined at smooth armpits."""

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
    shirt_torso,
    styled_upper_parts,
)
from data_prep.garments.shapes import Design
from data_prep.garments.style import Style, choice, number


@dataclasses.dataclass(frozen=True)
class TShirtStyle(Style):
    """A T-shirt (short or long sleeves, cropped to tunic length)."""

    garment_type: ClassVar[str] = "tshirt"
    length: float = number(0.5, 0.0, 1.0, "hem height: 0 = natural waist (cropped), 1 = 12 cm "
                           "below the crotch (tunic)")
    looseness: float = number(0.03, 0.015, 0.06, "ease around the torso (m)")
    sleeve_length: float = number(0.35, 0.15, 1.0, "fraction of shoulder-to-wrist length")
    sleeve_looseness: float = number(0.025, 0.015, 0.05, "ease around the arm (m)")
    sleeve_flare: float = number(0.03, 0.0, 0.12, "sleeve widening per metre along the arm")
    neckline: str = choice("round", NECKLINES, "neckline shape")
    neck_depth: float = number(0.05, 0.02, 0.14, "neckline depth in front, below the shoulder "
                               "line (m)")
    back_depth: float = number(0.02, 0.015, 0.04, "neckline depth at the back (m)")
    neck_width: float = number(0.015, 0.0, 0.05, "neckline width beyond the neck, each side (m)")
    front_rise: float = number(0.0, -0.03, 0.05, "hem higher in front than at the back (m)")


def tshirt_outline(body: BodyFrame, style: TShirtStyle) -> GarmentOutline:
    m = body.measurements
    z_hem, torso = shirt_torso(m, body.vertices, style.length, style.looseness)
    extra, cuts, loops, top = styled_upper_parts(
        body.vertices, m, torso, style, sleeves="sleeved", strap=0.0, armhole_drop=0.0,
        top_edge=0.0)
    solids = [torso, *extra]
    hem = hem_cut(z_hem, torso, front_rise=style.front_rise)
    design = Design(solids=solids, cuts=[hem, *cuts],
                    bounds=bounds(solids, hem_low(z_hem, style.front_rise),
                                  float(m.shoulder_z.max()) + 0.15))
    return GarmentOutline(design=design, loops=loops + 1, top=top)
