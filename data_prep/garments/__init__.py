"""Procedural garments (the synthetic CLOTH3D-like set's rest meshes).

Public API (arrays in metres, Z up, the body facing −Y; ``pos (N, 3)``, ``faces (F, 3)``):

* :class:`BodyFrame` — the body a garment is built around (vertices, faces, 24 SMPL-order
  joints); :func:`synthetic_body` a cheap stand-in, :func:`anny_body_frame` Anny's.
* :func:`make_garment` / :func:`sample_garment` → :class:`Garment` (name, type, style,
  pos, faces, pin_candidates, openings); :data:`GARMENT_TYPES` (skirt, trousers, tshirt,
  top, dress, jumpsuit) with their style dataclasses.
* :func:`garment_problems` — the validation every generated garment passes.
* :func:`flared_skirt` — a stand-alone irregular cone skirt (no body needed).

See ``docs/garments.md``.
"""

from data_prep.garments.anny_frame import anny_body_frame
from data_prep.garments.body_frame import BodyFrame, largest_component
from data_prep.garments.checks import garment_problems, self_intersections
from data_prep.garments.dress import DressStyle
from data_prep.garments.garment import (
    DEFAULT_RESOLUTION,
    GARMENT_TYPES,
    Garment,
    GarmentError,
    make_garment,
    sample_garment,
)
from data_prep.garments.jumpsuit import JumpsuitStyle
from data_prep.garments.skirt import SkirtStyle, flared_skirt
from data_prep.garments.synthetic_body import synthetic_body
from data_prep.garments.top import TopStyle
from data_prep.garments.trousers import TrousersStyle
from data_prep.garments.tshirt import TShirtStyle

__all__ = [
    "DEFAULT_RESOLUTION", "GARMENT_TYPES", "BodyFrame", "DressStyle", "Garment",
    "GarmentError", "JumpsuitStyle", "SkirtStyle", "TShirtStyle", "TopStyle", "TrousersStyle",
    "anny_body_frame", "flared_skirt", "garment_problems", "largest_component",
    "make_garment", "sample_garment", "self_intersections", "synthetic_body",
]
