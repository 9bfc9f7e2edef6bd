"""What a garment type hands to the mesher."""

from __future__ import annotations

import dataclasses

from data_prep.garments.shapes import Design


@dataclasses.dataclass
class GarmentOutline:
    """A garment type's output for one body and style.

    Attributes:
        design: the implicit garment (solids and cuts).
        loops: how many boundary loops (openings) the mesh must have.
        top: name of the opening whose loop is returned as ``pin_candidates``.
    """

    design: Design
    loops: int
    top: str
