"""`make_garment` / `sample_garment`, the whole generator: every type clean, around the
body and where clothes sit; resolution, styles, seeds, the sampler; on the synthetic body
(T- and A-pose, another build) and on Anny bodies (T- and A-pose, two shapes)."""

from __future__ import annotations

import numpy as np
import pytest

from data_prep.garments import (
    GARMENT_TYPES,
    BodyFrame,
    GarmentError,
    SkirtStyle,
    TShirtStyle,
    garment_problems,
    make_garment,
    sample_garment,
    synthetic_body,
)
from gnngarment.geometry import check_mesh, vertex_normals

OPENINGS = {
    "skirt": {"waist", "hem"},
    "trousers": {"waist", "leg_L", "leg_R"},
    "tshirt": {"neck", "hem", "cuff_L", "cuff_R"},
    "top": {"neck", "hem", "armhole_L", "armhole_R"},
    "dress": {"neck", "hem", "armhole_L", "armhole_R"},
    "jumpsuit": {"neck", "leg_L", "leg_R", "armhole_L", "armhole_R"},
}
TOP_OPENING = {"skirt": "waist", "trousers": "waist", "tshirt": "neck", "top": "neck",
               "dress": "neck", "jumpsuit": "neck"}


@pytest.mark.parametrize("kind", sorted(GARMENT_TYPES))
def test_each_type_is_a_valid_garment(garments: dict, body: BodyFrame, kind: str) -> None:
    garment = garments[kind]
    assert garment.garment_type == kind
    # Everything make_garment promises, re-checked here with a 5 mm clearance.
    assert garment_problems(garment, body, expected_openings=len(OPENINGS[kind]),
                            clearance=0.005) == []
    report = check_mesh(garment.pos, garment.faces)
    assert report.ok and not report.findings
    assert len(report.non_manifold_edges) == 0 and report.num_components == 1
    assert set(garment.openings) == OPENINGS[kind]
    assert abs(garment.num_vertices - 1500) < 0.08 * 1500


@pytest.mark.parametrize("kind", sorted(GARMENT_TYPES))
def test_openings_are_boundary_loops_and_pins_are_the_top_one(garments: dict, kind: str) -> None:
    garment = garments[kind]
    faces = garment.faces
    directed = {(int(a), int(b)) for f in faces for a, b in ((f[0], f[1]), (f[1], f[2]),
                                                             (f[2], f[0]))}
    border = {edge for edge in directed if edge[::-1] not in directed}
    loop_edges = set()
    for loop in garment.openings.values():
        assert len(loop) >= 8
        for a, b in zip(loop, np.roll(loop, -1), strict=True):
            assert (int(a), int(b)) in border or (int(b), int(a)) in border
            loop_edges.add((int(a), int(b)))
    assert len(loop_edges) == len(border)  # the openings are all of the boundary
    assert np.array_equal(garment.pin_candidates, garment.openings[TOP_OPENING[kind]])
    heights = {name: garment.pos[loop, 2].mean() for name, loop in garment.openings.items()}
    assert max(heights, key=heights.get) == TOP_OPENING[kind]


def test_garments_sit_where_clothes_sit(garments: dict, body: BodyFrame) -> None:
    m = body.measurements
    waist = garments["skirt"].pos[garments["skirt"].openings["waist"]]
    assert m.z_hip - 0.01 < waist[:, 2].mean() < m.z_waist + 0.01
    assert np.linalg.norm(waist[:, :2].mean(axis=0) - body.joint("pelvis")[:2]) < 0.03
    hem = garments["skirt"].pos[garments["skirt"].openings["hem"]]
    assert m.z_ankle < hem[:, 2].mean() < m.z_crotch
    shirt = garments["tshirt"]
    for side in ("L", "R"):
        # Each cuff surrounds its arm: the loop's centre is on the arm's axis.
        cuff = shirt.pos[shirt.openings[f"cuff_{side}"]]
        arm = m.arms[side]
        t = np.linspace(0, arm.length, 200)
        assert np.min(np.linalg.norm(arm.point(t) - cuff.mean(axis=0), axis=1)) < 0.02
        assert np.sign(cuff[:, 0].mean()) == (1 if side == "L" else -1)
    neck = shirt.pos[shirt.openings["neck"]]
    assert abs(neck[:, 0].mean() - body.joint("neck")[0]) < 0.02
    trousers = garments["trousers"]
    for side, sign in (("L", 1), ("R", -1)):
        leg = trousers.pos[trousers.openings[f"leg_{side}"]]
        assert np.sign(leg[:, 0].mean()) == sign and leg[:, 2].mean() < m.z_knee + 0.2


def test_normals_face_away_from_the_body(garments: dict, body: BodyFrame) -> None:
    for garment in garments.values():
        _, _, away = body.distance.query(garment.pos)
        agree = np.einsum("ij,ij->i", vertex_normals(garment.pos, garment.faces), away) > 0
        assert agree.mean() > 0.95, garment.name


def test_triangulations_are_irregular(garments: dict) -> None:
    for garment in garments.values():
        valence = np.bincount(garment.faces.ravel(), minlength=garment.num_vertices)
        interior = np.ones(garment.num_vertices, dtype=bool)
        for loop in garment.openings.values():
            interior[loop] = False
        values = np.unique(valence[interior])
        assert values.min() <= 5 and values.max() >= 7 and len(values) >= 4, garment.name


def test_resolution_controls_the_vertex_count(body: BodyFrame) -> None:
    style = TShirtStyle(sleeve_length=0.6)
    for target in (500, 2500, 8000):
        garment = make_garment(body, "tshirt", style, target_vertices=target, seed=1)
        assert abs(garment.num_vertices - target) < 0.08 * target


def test_style_parameters_change_the_shape(body: BodyFrame) -> None:
    short = make_garment(body, "skirt", {"length": 0.2, "flare": 0.0}, target_vertices=800)
    long = make_garment(body, "skirt", {"length": 0.8, "flare": 0.5}, target_vertices=800)
    assert long.pos[:, 2].min() < short.pos[:, 2].min() - 0.2
    assert np.ptp(long.pos[:, 0]) > np.ptp(short.pos[:, 0]) + 0.2
    sleeves = [make_garment(body, "tshirt", {"sleeve_length": s}, target_vertices=800)
               for s in (0.2, 0.9)]
    assert np.ptp(sleeves[1].pos[:, 0]) > np.ptp(sleeves[0].pos[:, 0]) + 0.3
    deep = make_garment(body, "top", {"neck_depth": 0.15, "neckline": "v"}, target_vertices=800)
    shallow = make_garment(body, "top", {"neck_depth": 0.03}, target_vertices=800)
    assert deep.pos[deep.openings["neck"], 2].min() < shallow.pos[shallow.openings["neck"], 2].min()
    strapless = make_garment(body, "top", {"kind": "strapless"}, target_vertices=800)
    assert set(strapless.openings) == {"top", "hem"}


def test_make_garment_is_seeded(body: BodyFrame) -> None:
    a = make_garment(body, "dress", target_vertices=700, seed=5)
    b = make_garment(body, "dress", target_vertices=700, seed=5)
    c = make_garment(body, "dress", target_vertices=700, seed=6)
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.faces, b.faces)
    assert not np.array_equal(a.faces, c.faces)


def test_bad_requests_are_rejected(body: BodyFrame) -> None:
    with pytest.raises(ValueError, match="unknown garment type"):
        make_garment(body, "poncho")
    with pytest.raises(ValueError, match="flare"):
        make_garment(body, "skirt", {"flare": 5.0})
    with pytest.raises(ValueError, match="unknown skirt style"):
        make_garment(body, "skirt", {"sleeves": 1.0})
    with pytest.raises(ValueError, match="neckline"):
        TShirtStyle(neckline="turtle")
    with pytest.raises(ValueError, match="target_vertices"):
        make_garment(body, "skirt", target_vertices=50)
    with pytest.raises(ValueError, match=r"\(24, 3\)"):
        BodyFrame(body.vertices, body.faces, body.joints[:10])
    with pytest.raises(ValueError, match="out of range"):
        BodyFrame(body.vertices, body.faces + len(body.vertices), body.joints)


def test_sampler_gives_100_distinct_valid_garments(body: BodyFrame) -> None:
    rng = np.random.default_rng(2024)
    samples = [sample_garment(body, rng, resolution=(300, 600)) for _ in range(100)]
    assert {g.garment_type for g in samples} == set(GARMENT_TYPES)
    # Every sample passed garment_problems inside make_garment; spot-check a few again.
    for garment in samples[::20]:
        assert garment_problems(garment, body, clearance=0.005) == []
    keys = [(g.garment_type, g.num_vertices, tuple(np.round(g.pos.min(0), 3)),
             tuple(np.round(g.pos.max(0), 3))) for g in samples]
    assert len(set(keys)) == 100
    assert len({tuple(sorted(g.style.items())) for g in samples}) == 100
    assert len({g.name for g in samples}) == 100


def test_sampler_is_seeded_and_respects_the_type(body: BodyFrame) -> None:
    a = sample_garment(body, 11, "trousers", resolution=(400, 500))
    b = sample_garment(body, np.random.default_rng(11), "trousers", resolution=(400, 500))
    assert a.garment_type == "trousers" and a.name == b.name
    assert np.array_equal(a.pos, b.pos)
    with pytest.raises(ValueError, match="unknown garment type"):
        sample_garment(body, 0, "cape")


def test_a_pose_body(body: BodyFrame) -> None:
    a_pose = synthetic_body(arm_angle_deg=40.0)
    for kind in ("tshirt", "skirt", "trousers"):
        garment = sample_garment(a_pose, 7, kind, resolution=(600, 900))
        assert garment_problems(garment, a_pose, clearance=0.005) == []


def test_other_body_builds() -> None:
    wide = synthetic_body(girth=1.25, scale=0.92)
    garment = sample_garment(wide, 3, "dress", resolution=(600, 900))
    assert garment_problems(garment, wide, clearance=0.005) == []


def test_garment_error_is_a_value_error() -> None:
    assert issubclass(GarmentError, ValueError)
    assert SkirtStyle.describe()[0][0] == "waist_height"


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
