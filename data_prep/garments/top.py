"""Tops: sleeveless (straps of any width, armholes) or strapless (a tube top)."""

from __future__ import annotations

import dataclasses
from typing import ClassVar

from data_prep.garments.body_frame import BodyFrame
from data_prep.garments.outline import GarmentOutline
from data_prep.garments.parts import NECKLINES, bounds, hem_cut, shirt_torso, styled_upper_parts
from data_prep.garments.shapes import Design
from data_prep.garments.style import Style, choice, number


@dataclasses.dataclass(frozen=True)
class TopStyle(Style):
    """A sleeveless top: tank top / camisole (straps) or tube top (strapless)."""

    garment_type: ClassVar[str] = "top"
    kind: str = choice("straps", ("straps", "strapless"), "shoulder straps or a straight top "
                       "edge", weights=(3.0, 1.0))
    length: float = number(0.5, 0.0, 1.0, "hem height: 0 = natural waist, 1 = 12 cm below the "
                           "crotch")
    looseness: float = number(0.025, 0.015, 0.06, "ease around the torso (m)")
    strap: float = number(0.05, 0.025, 0.1, "shoulder strap width (m)")
    armhole_drop: float = number(0.02, 0.0, 0.07, "armhole depth below the armpit (m)")
    neckline: str = choice("round", NECKLINES, "neckline shape")
    neck_depth: float = number(0.08, 0.03, 0.16, "neckline depth in front (m)")
    back_depth: float = number(0.03, 0.015, 0.08, "neckline depth at the back (m)")
    neck_width: float = number(0.02, 0.0, 0.05, "neckline width beyond the neck, each side (m)")
    top_edge: float = number(0.04, 0.01, 0.1, "strapless: top edge below the armpits (m)")


def top_outline(body: BodyFrame, style: TopStyle) -> GarmentOutline:
    m = body.measurements
    z_hem, torso = shirt_torso(m, body.vertices, style.length, style.looseness)
    sleeves = "strapless" if style.kind == "strapless" else "sleeveless"
    extra, cuts, loops, top = styled_upper_parts(
        body.vertices, m, torso, style, sleeves=sleeves, sleeve_length=0.0,
        sleeve_looseness=0.0, sleeve_flare=0.0)
    solids = [torso, *extra]
    design = Design(solids=solids, cuts=[hem_cut(z_hem, torso), *cuts],
                    bounds=bounds(solids, z_hem - 0.03, float(m.shoulder_z.max()) + 0.15))
    return GarmentOutline(design=design, loops=loops + 1, top=top)
