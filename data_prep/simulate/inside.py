"""Signed distance of points to a closed triangle mesh (inside/outside of the body).

The implementation lives in :mod:`gnngarment.geometry.signed_distance` (the learned
model's collision resolution uses the same Warp queries); this module keeps the names
the simulator and its tests import.
"""

from __future__ import annotations

from gnngarment.geometry.signed_distance import (
    SEARCH_RADIUS,
    signed_distance,
    signed_distance_warp,
)

__all__ = ["SEARCH_RADIUS", "signed_distance", "signed_distance_warp"]
