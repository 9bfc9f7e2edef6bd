"""Bodies and garments shared by the tests of `data_prep/garments/`, each built once per
session: the synthetic body, one default garment per type on it, and Anny bodies.

Anny is constructed once (the first construction on a fresh machine builds its cache,
about a minute); everything else runs on its rest meshes.
"""

from __future__ import annotations

import pytest

from data_prep.garments import (
    GARMENT_TYPES,
    BodyFrame,
    anny_body_frame,
    make_garment,
    synthetic_body,
)


@pytest.fixture(scope="session")
def body() -> BodyFrame:
    return synthetic_body(arm_angle_deg=0.0)


@pytest.fixture(scope="session")
def garments(body: BodyFrame) -> dict:
    """One garment per type, default style, 1500 vertices."""
    return {kind: make_garment(body, kind, target_vertices=1500, seed=3) for kind in GARMENT_TYPES}


@pytest.fixture(scope="session")
def anny_bodies() -> dict[str, BodyFrame]:
    anny = pytest.importorskip("anny")

    model = anny.Anny()
    return {
        "T": anny_body_frame(model, "T"),
        "A": anny_body_frame(model, "A"),
        "heavy_T": anny_body_frame(model, "T", {"gender": 1.0, "age": 0.7, "weight": 0.9,
                                                "height": 0.35}),
    }
