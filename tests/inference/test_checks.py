"""Garment placement checks: one test per mistake, plus the fixes."""

from __future__ import annotations

import numpy as np
import pytest

from gnngarment.inference.checks import (
    Z_UP_FROM_Y_UP,
    check_garment_placement,
    detect_units,
    fix_placement,
    inside_fraction,
)
from tests.inference.animations import rest_body, rest_garment
from tests.meshes import tube


@pytest.fixture(scope="module")
def body():
    return rest_body()


@pytest.fixture(scope="module")
def garment():
    return rest_garment()


def codes(findings) -> list[tuple[str, str]]:
    return [(f.code, f.severity) for f in findings]


def test_a_well_placed_garment_has_no_findings(body, garment) -> None:
    assert check_garment_placement(*garment, *body) == []


@pytest.mark.parametrize(("unit", "scale"), [("cm", 100.0), ("mm", 1000.0)])
def test_centimetres_and_millimetres(body, garment, unit, scale) -> None:
    findings = check_garment_placement(garment[0] * scale, garment[1], *body)
    assert codes(findings) == [("units", "error")]
    assert findings[0].fix == {"units": unit}
    assert f"{scale * 0.44:.0f}×" in findings[0].message  # garment/body diagonal ratio
    fixed, message = fix_placement(garment[0] * scale, units="auto", body_vertices=body[0])
    np.testing.assert_allclose(fixed, garment[0])
    assert message.startswith(f"scaled {'centimetres' if unit == 'cm' else 'millimetres'}")


def test_implausible_size_is_reported_without_a_fix(body, garment) -> None:
    findings = check_garment_placement(garment[0] * 10.0, garment[1], *body)
    assert findings[0].code == "units" and findings[0].fix == {}
    assert detect_units(garment[0] * 10.0, body[0]) is None
    assert detect_units(garment[0] * 100.0) == "cm"  # no body: an adult's size is assumed


def test_y_up_garment(body, garment) -> None:
    y_up = garment[0] @ Z_UP_FROM_Y_UP  # the inverse turn: Z up → Y up
    findings = check_garment_placement(y_up, garment[1], *body)
    assert codes(findings) == [("up_axis", "error")]
    fixed, message = fix_placement(y_up, units="m", up_axis="y")
    np.testing.assert_allclose(fixed, garment[0], atol=1e-12)
    assert "Y-up to Z-up" in message
    fixed, _ = fix_placement(y_up, up_axis="auto", body_vertices=body[0], body_faces=body[1])
    np.testing.assert_allclose(fixed, garment[0], atol=1e-12)


def test_y_up_garment_turned_about_the_pelvis(body) -> None:
    # Body models with the origin at the pelvis: a wrongly turned skirt stays near the
    # body (no distance cue) but cuts through it.
    from data_prep.garments import flared_skirt

    centred = (body[0] - np.array([0.0, 0.0, 0.95]), body[1])
    pos, faces = flared_skirt(1500, waist_radius=0.155, hem_radius=0.42, length=0.55, seed=3)
    pos = pos + np.array([0.0, 0.0, 0.05])
    assert check_garment_placement(pos, faces, *centred) == []  # flared, yet not "floating"
    findings = check_garment_placement(pos @ Z_UP_FROM_Y_UP, faces, *centred)
    assert codes(findings) == [("up_axis", "error")]


def test_centimetres_and_y_up_together(body, garment) -> None:
    wrong = 100.0 * garment[0] @ Z_UP_FROM_Y_UP
    findings = check_garment_placement(wrong, garment[1], *body)
    assert codes(findings) == [("units", "error"), ("up_axis", "error")]
    fixed, message = fix_placement(wrong, units="cm", up_axis="y")
    np.testing.assert_allclose(fixed, garment[0], atol=1e-9)
    assert message == ("scaled centimetres to metres (×0.01); "
                       "turned Y-up to Z-up ((x, y, z) → (x, −z, y))")


def test_far_from_the_body(body, garment) -> None:
    findings = check_garment_placement(garment[0] + [3.0, 0.0, 0.0], garment[1], *body)
    assert codes(findings) == [("far_from_body", "error")]
    centre = (garment[0].min(axis=0) + garment[0].max(axis=0)) / 2
    body_centre = (body[0].min(axis=0) + body[0].max(axis=0)) / 2
    dz = centre[2] - body_centre[2]
    assert f"offset (x, y, z) = (+3.00, +0.00, {dz:+.2f}) m" in findings[0].message


def test_above_the_head_or_below_the_soles(body, garment) -> None:
    """A garment whose box still overlaps the body's but reaches well above the head (or
    below the feet) was placed in another frame, however close to the body it is: the
    CLOTH3D starter kit's world-frame trousers landed around the head."""
    top = body[0][:, 2].max()
    lifted = garment[0] + np.array([0.0, 0.0, top - garment[0][:, 2].min() - 0.2])
    findings = check_garment_placement(lifted, garment[1], *body)
    assert codes(findings) == [("beyond_body", "error")]
    assert "above the top of the body's head" in findings[0].message
    bottom = body[0][:, 2].min()
    dropped = garment[0] + np.array([0.0, 0.0, bottom - garment[0][:, 2].max() + 0.1])
    assert "below the body's soles" in check_garment_placement(dropped, garment[1],
                                                               *body)[0].message


def test_floating_away_from_the_body(body) -> None:
    wide, faces = tube(6, 24, radius=0.8, height=0.4)
    findings = check_garment_placement(wide + np.array([0.0, 0.0, 0.6]), faces, *body)
    assert codes(findings) == [("far_from_body", "warning")]


def test_inside_the_body(body) -> None:
    narrow, faces = tube(6, 24, radius=0.08, height=0.4)
    findings = check_garment_placement(narrow + np.array([0.0, 0.0, 0.6]), faces, *body)
    assert codes(findings) == [("intersects_body", "error")]
    assert findings[0].message.startswith("100% of the garment's vertices")


def test_partly_inside_the_body_is_a_warning(body) -> None:
    # A tube pushed sideways: 7 of its 32 columns (22%) pass through the body.
    pos, faces = tube(6, 32, radius=0.18, height=0.4)
    findings = check_garment_placement(pos + np.array([0.08, 0.0, 0.6]), faces, *body)
    assert codes(findings) == [("intersects_body", "warning")]
    assert 15 <= int(findings[0].message.split("%")[0]) <= 30


def test_inside_fraction_follows_the_true_inside_of_a_capsule(body) -> None:
    rng = np.random.default_rng(0)
    points = rng.uniform([-0.3, -0.3, 0.4], [0.3, 0.3, 1.2], size=(4000, 3))
    radial = np.linalg.norm(points[:, :2], axis=1)
    truth = np.mean(radial < 0.14 - 0.005)
    assert inside_fraction(points, *body) == pytest.approx(truth, abs=0.02)
    # Inward-wound faces are detected and do not flip the answer.
    assert inside_fraction(points, body[0], body[1][:, ::-1]) == pytest.approx(truth, abs=0.02)


def test_validation(body, garment) -> None:
    with pytest.raises(ValueError, match=r"pos must be \(N, 3\)"):
        check_garment_placement(np.zeros((3, 2)), garment[1], *body)
    with pytest.raises(ValueError, match="NaN"):
        check_garment_placement(np.full((3, 3), np.nan), np.array([[0, 1, 2]]), *body)
    with pytest.raises(ValueError, match="faces must be"):
        check_garment_placement(garment[0], np.array([[0, 1, 9999]]), *body)
    with pytest.raises(ValueError, match="units must be"):
        fix_placement(garment[0], units="inch")
    with pytest.raises(ValueError, match="up_axis must be"):
        fix_placement(garment[0], up_axis="x")
    with pytest.raises(ValueError, match="needs body_vertices"):
        fix_placement(garment[0], up_axis="auto")
    assert fix_placement(garment[0], units="auto")[1] == "kept as given (metres, Z up)"


def test_explicit_scale_and_offset(body, garment) -> None:
    """A mesh in an unknown unit (×10: no rule guesses it) with its feet at the origin:
    ``--scale`` and ``--offset`` put it back exactly, and say so."""
    moved = (garment[0] - [0.0, 0.0, -0.8]) * 10.0
    assert detect_units(moved, body[0]) is None
    fixed, message = fix_placement(moved, scale=0.1, offset=np.array([0.0, 0.0, -0.8]),
                                   body_vertices=body[0])
    np.testing.assert_allclose(fixed, garment[0], atol=1e-12)
    assert "scaled by 0.1 (given)" in message and "moved by (+0.000, +0.000, -0.800)" in message
    assert check_garment_placement(fixed, garment[1], *body) == []


@pytest.mark.parametrize(("options", "problem"), [
    ({"scale": 0.0}, "scale must be a finite number > 0"),
    ({"scale": float("nan")}, "scale must be a finite number > 0"),
    ({"scale": 0.01, "units": "cm"}, "either a scale or units"),
    ({"offset": np.array([0.0, np.inf, 0.0])}, "offset must be 3 finite numbers"),
    ({"offset": np.array([0.0, 1.0])}, "offset must be 3 finite numbers"),
])
def test_explicit_placement_is_validated(garment, options, problem) -> None:
    with pytest.raises(ValueError, match=problem):
        fix_placement(garment[0], **options)


REAL_GARMENTS = (__import__("pathlib").Path(__file__).resolve().parents[2].parent / "shared"
                 / "real-world" / "garments")
#: The real garments modelled Y up (../shared/real-world/README.md).
Y_UP_GARMENTS = ("snug_tank", "snug_shorts", "snug_long_sleeve_top", "vto_dress", "ncs_tshirt",
                 "ncs_pants", "ncs_mannequin_tshirt", "diffcloth_skirt3448",
                 "diffcloth_dress_v5k")


@pytest.mark.skipif(not REAL_GARMENTS.is_dir(), reason="../shared/real-world is absent "
                    "(third-party test data beside the repository, not in a clone)")
def test_up_axis_of_real_garments_made_on_other_bodies(anny_rest) -> None:
    """Every Y-up garment of the real-world set is recognised as Y up on our body, and
    the Z-up ones (PBNS, CLOTH3D) are left alone, although SMPL-made garments intersect
    our body more once turned (it is another body)."""
    from gnngarment.geometry.mesh_io import load_mesh
    from gnngarment.inference.checks import UNIT_SCALES, detect_up_axis

    body = anny_rest.vertices.numpy().astype(np.float64), anny_rest.faces
    found = {}
    for path in sorted(REAL_GARMENTS.glob("*.obj")):
        pos, _ = load_mesh(path)
        pos = pos * UNIT_SCALES[detect_units(pos, body[0]) or "m"]
        found[path.stem] = detect_up_axis(pos, *body)
    assert found == {name: "y" if name in Y_UP_GARMENTS else "z" for name in found}, found


@pytest.mark.skipif(not REAL_GARMENTS.is_dir(), reason="../shared/real-world is absent "
                    "(third-party test data beside the repository, not in a clone)")
def test_world_frame_cloth3d_trousers_are_refused_and_the_others_are_not(anny_rest) -> None:
    """The starter kit's trousers (world frame, feet at z = 0) are refused; none of the
    real garments on their own is flagged as reaching beyond our body."""
    from gnngarment.geometry.mesh_io import load_mesh
    from gnngarment.inference.checks import fix_placement

    body = anny_rest.vertices.numpy().astype(np.float64), anny_rest.faces
    trousers, faces = load_mesh(REAL_GARMENTS.parent / "cloth3d" / "starterkit" / "Trousers.obj")
    assert "beyond_body" in [f.code for f in check_garment_placement(trousers, faces, *body)]
    for path in sorted(REAL_GARMENTS.glob("*.obj")):
        pos, faces = load_mesh(path)
        fixed, _ = fix_placement(pos, units="auto", up_axis="auto", body_vertices=body[0],
                                 body_faces=body[1])
        codes_found = [f.code for f in check_garment_placement(fixed, faces, *body)]
        assert "beyond_body" not in codes_found, path.name
