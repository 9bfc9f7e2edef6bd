"""Procedural garments on the synthetic body (fast): validity, fit, sampler, validators."""

from __future__ import annotations

import time

import numpy as np
import pytest

from data_prep.garments import (
    GARMENT_TYPES,
    BodyFrame,
    Garment,
    GarmentError,
    SkirtStyle,
    TShirtStyle,
    flared_skirt,
    garment_problems,
    make_garment,
    sample_garment,
    self_intersections,
    synthetic_body,
)
from data_prep.garments.body_distance import BodyDistance
from data_prep.garments.flips import delaunay_flips
from data_prep.garments.measurements import ARM_L, ARM_R, HEAD, TRUNK
from gnngarment.body.skeleton import JOINT_INDEX
from gnngarment.geometry import (
    check_mesh,
    connected_components,
    edge_index_from_faces,
    vertex_normals,
)

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


@pytest.fixture(scope="module")
def body() -> BodyFrame:
    return synthetic_body(arm_angle_deg=0.0)


@pytest.fixture(scope="module")
def garments(body: BodyFrame) -> dict:
    """One garment per type, default style, 1500 vertices."""
    return {kind: make_garment(body, kind, target_vertices=1500, seed=3) for kind in GARMENT_TYPES}


# ---- the stand-alone cone skirt (used by the demo and benchmarks) ---------------------


def test_flared_skirt_is_a_clean_outward_facing_tube() -> None:
    pos, faces = flared_skirt(1500, waist_radius=0.15, hem_radius=0.4, length=0.5, seed=3)
    report = check_mesh(pos, faces)
    assert report.ok and not report.findings, report.errors + report.findings
    assert abs(len(pos) - 1500) < 20
    assert connected_components(edge_index_from_faces(faces, len(pos)), len(pos)).max() == 0
    radial = pos[:, :2] / np.linalg.norm(pos[:, :2], axis=1, keepdims=True)
    assert (np.einsum("ij,ij->i", vertex_normals(pos, faces)[:, :2], radial) > 0).all()
    top, bottom = pos[:, 2] > -1e-9, pos[:, 2] < -0.5 + 1e-9
    np.testing.assert_allclose(np.linalg.norm(pos[top, :2], axis=1), 0.15)
    np.testing.assert_allclose(np.linalg.norm(pos[bottom, :2], axis=1), 0.4)


def test_flared_skirt_is_seeded() -> None:
    a, _ = flared_skirt(400, seed=1)
    b, _ = flared_skirt(400, seed=1)
    c, _ = flared_skirt(400, seed=2)
    assert np.array_equal(a, b) and not np.array_equal(a, c)


# ---- every type: clean, around the body, where clothes sit ---------------------------


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


# ---- parameters: resolution, styles, seeds -------------------------------------------


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


def test_generation_is_fast(body: BodyFrame) -> None:
    make_garment(body, "tshirt", target_vertices=3000, seed=0)  # warm-up (imports)
    start = time.process_time()
    make_garment(body, "jumpsuit", {"sleeves": "sleeved"}, target_vertices=3000, seed=0)
    # ~0.5 s of CPU on an idle 2-core machine, validation included; generous bound.
    assert time.process_time() - start < 3.0


def test_a_pose_body(body: BodyFrame) -> None:
    a_pose = synthetic_body(arm_angle_deg=40.0)
    for kind in ("tshirt", "skirt", "trousers"):
        garment = sample_garment(a_pose, 7, kind, resolution=(600, 900))
        assert garment_problems(garment, a_pose, clearance=0.005) == []


def test_other_body_builds() -> None:
    wide = synthetic_body(girth=1.25, scale=0.92)
    garment = sample_garment(wide, 3, "dress", resolution=(600, 900))
    assert garment_problems(garment, wide, clearance=0.005) == []


# ---- the body as arrays --------------------------------------------------------------


def test_synthetic_body_and_measurements(body: BodyFrame) -> None:
    assert 1.55 < np.ptp(body.vertices[:, 2]) < 1.7
    m = body.measurements
    labels = m.labels
    wrist = body.joint("L_wrist")
    near_wrist = np.linalg.norm(body.vertices - wrist, axis=1) < 0.04
    assert (labels[near_wrist] == ARM_L).all()
    assert (labels[np.linalg.norm(body.vertices - body.joint("R_wrist"), axis=1) < 0.04]
            == ARM_R).all()
    assert (labels[body.vertices[:, 2] > 0.7] == HEAD).all()
    assert (labels[np.abs(body.vertices[:, 2] - 0.2) < 0.01] == TRUNK).all()
    assert body.joint("R_knee")[2] < m.z_crotch < body.joint("pelvis")[2]
    assert abs(m.neck_radius - 0.055) < 0.01
    # The chest section holds the chest ellipsoid (half-width 0.16 m).
    chest = m.trunk.at(0.37)
    assert 0.16 <= chest["a"] < 0.2
    assert m.armpits["L"][0] > 0 > m.armpits["R"][0]


def test_body_distance_on_a_sphere() -> None:
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.2)
    distance = BodyDistance(sphere.vertices, sphere.faces)
    rng = np.random.default_rng(0)
    points = rng.uniform(-0.35, 0.35, (2000, 3))
    signed = distance(points)
    exact = np.linalg.norm(points, axis=1) - 0.2
    np.testing.assert_allclose(signed, exact, atol=2e-3)  # chordal error of the mesh
    inside, bound = distance.clearance(points, threshold=0.05)
    far = np.abs(exact) > 3e-3
    assert np.array_equal(inside[far], exact[far] < 0)
    assert (bound <= np.abs(signed) + 1e-12).all()
    # Two overlapping spheres: the union's distance is the minimum.
    shifted = np.asarray(sphere.vertices) + np.array([0.3, 0.0, 0.0])
    union = BodyDistance(np.concatenate([sphere.vertices, shifted]),
                         np.concatenate([sphere.faces, sphere.faces + len(sphere.vertices)]))
    both = np.minimum(exact, np.linalg.norm(points - [0.3, 0, 0], axis=1) - 0.2)
    np.testing.assert_allclose(union(points), both, atol=2e-3)


# ---- validators ----------------------------------------------------------------------


def test_self_intersections_on_tiny_cases() -> None:
    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0],
                    [0.2, 0.2, -0.5], [0.3, 0.2, 0.5], [0.2, 0.3, 0.5]], dtype=float)
    assert len(self_intersections(pos, np.array([[0, 1, 2], [3, 4, 5]]))) == 1
    apart = pos + np.array([[0, 0, 0]] * 3 + [[5, 0, 0]] * 3)
    assert len(self_intersections(apart, np.array([[0, 1, 2], [3, 4, 5]]))) == 0
    # Triangles sharing a vertex are not reported.
    assert len(self_intersections(pos, np.array([[0, 1, 2], [0, 4, 5]]))) == 0


def test_garment_problems_catches_defects(garments: dict, body: BodyFrame) -> None:
    garment = garments["tshirt"]
    assert garment_problems(garment, body) == []
    flipped = _copy(garment)
    flipped.faces[0] = flipped.faces[0, ::-1]
    assert any("orientation" in p for p in garment_problems(flipped, body))
    inside = _copy(garment)
    chest = int(np.argmin(np.linalg.norm(inside.pos - body.joint("spine3"), axis=1)))
    inside.pos[chest] = body.joint("spine3")
    assert any("inside the body" in p for p in garment_problems(inside, body))
    # A chest vertex pulled through to behind the back: its triangles cross the back.
    through = _copy(garment)
    chest = np.flatnonzero(np.abs(through.pos[:, 2] - body.joint("spine3")[2]) < 0.03)
    front = chest[np.argmin(through.pos[chest, 1])]
    through.pos[front, 1] = through.pos[:, 1].max() + 0.05
    assert any("self-intersecting" in p for p in garment_problems(through, body))
    inward = _copy(garment)
    inward.faces = inward.faces[:, ::-1].copy()
    assert any("face away" in p for p in garment_problems(inward, body))
    assert any("boundary loops" in p for p in garment_problems(garment, body, 3))


def test_delaunay_flips_keep_a_valid_mesh(garments: dict) -> None:
    garment = garments["dress"]
    rng = np.random.default_rng(0)
    noisy = garment.pos + rng.normal(0, 0.004, garment.pos.shape)
    faces = delaunay_flips(noisy, garment.faces)
    report = check_mesh(noisy, faces)
    assert report.ok and not report.findings
    assert len(faces) == len(garment.faces)


def _copy(garment: Garment) -> Garment:
    import dataclasses

    return dataclasses.replace(garment, pos=garment.pos.copy(), faces=garment.faces.copy())


def test_joint_table_is_smpl_order() -> None:
    assert JOINT_INDEX["pelvis"] == 0 and JOINT_INDEX["neck"] == 12 and JOINT_INDEX["R_hand"] == 23


def test_garment_error_is_a_value_error() -> None:
    assert issubclass(GarmentError, ValueError)
    assert SkirtStyle.describe()[0][0] == "waist_height"
