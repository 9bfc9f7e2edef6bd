"""Procedural garments on Anny bodies (T- and A-pose, two shapes).

Anny is constructed once for the module (the first construction on a fresh machine
builds its cache, about a minute); everything else runs on its rest meshes.
"""

from __future__ import annotations

import numpy as np
import pytest

from data_prep.garments import (
    GARMENT_TYPES,
    BodyFrame,
    anny_body_frame,
    garment_problems,
    make_garment,
    sample_garment,
)

pytest.importorskip("anny")


@pytest.fixture(scope="session")
def anny_bodies() -> dict[str, BodyFrame]:
    import anny

    model = anny.Anny()
    return {
        "T": anny_body_frame(model, "T"),
        "A": anny_body_frame(model, "A"),
        "heavy_T": anny_body_frame(model, "T", {"gender": 1.0, "age": 0.7, "weight": 0.9,
                                                "height": 0.35}),
    }


def test_anny_frames(anny_bodies: dict[str, BodyFrame]) -> None:
    import trimesh

    for name, body in anny_bodies.items():
        mesh = trimesh.Trimesh(body.vertices, body.faces, process=False)
        assert mesh.is_watertight and mesh.volume > 0, name
        assert abs(body.joint("pelvis")[2]) < 0.1 and body.vertices[:, 2].max() > 0.6
    t_pose, a_pose = anny_bodies["T"], anny_bodies["A"]
    for body, straight in ((t_pose, True), (a_pose, False)):
        drop = body.joint("L_shoulder")[2] - body.joint("L_wrist")[2]
        assert (abs(drop) < 0.03) == straight
    assert t_pose.joint("L_wrist")[0] > 0.6 and a_pose.joint("L_wrist")[0] < 0.5


@pytest.mark.parametrize("kind", sorted(GARMENT_TYPES))
def test_each_type_fits_the_t_pose(anny_bodies: dict[str, BodyFrame], kind: str) -> None:
    body = anny_bodies["T"]
    garment = make_garment(body, kind, target_vertices=1500, seed=1)
    assert garment_problems(garment, body, clearance=0.005) == []
    m = body.measurements
    top = garment.pos[garment.pin_candidates]
    if kind in ("skirt", "trousers"):
        # The waistband circles the pelvis between the hip joints and the natural waist.
        assert m.z_hip - 0.01 < top[:, 2].mean() < m.z_waist + 0.01
        assert np.linalg.norm(top[:, :2].mean(axis=0) - body.joint("pelvis")[:2]) < 0.04
    else:
        # The neckline circles the neck.
        assert abs(top[:, 0].mean() - body.joint("neck")[0]) < 0.02
        assert top[:, 2].max() > m.z_shoulder
    if kind == "tshirt":
        for side in ("L", "R"):
            cuff = garment.pos[garment.openings[f"cuff_{side}"]].mean(axis=0)
            arm = m.arms[side]
            on_axis = arm.point(np.linspace(0, arm.length, 300))
            assert np.min(np.linalg.norm(on_axis - cuff, axis=1)) < 0.02


def test_a_pose_garments(anny_bodies: dict[str, BodyFrame]) -> None:
    body = anny_bodies["A"]
    for kind in ("tshirt", "skirt", "trousers", "dress"):
        garment = sample_garment(body, 5, kind, resolution=(1000, 2000))
        assert garment_problems(garment, body, clearance=0.005) == []


def test_samples_on_another_shape(anny_bodies: dict[str, BodyFrame]) -> None:
    body = anny_bodies["heavy_T"]
    rng = np.random.default_rng(3)
    for kind in sorted(GARMENT_TYPES):
        garment = sample_garment(body, rng, kind, resolution=(800, 2500))
        assert garment_problems(garment, body, clearance=0.005) == []
