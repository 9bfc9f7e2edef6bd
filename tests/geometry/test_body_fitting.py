"""Fitting a garment made on another body onto the rest body (issue 13)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gnngarment.geometry.body_fitting import (
    align_bodies,
    axis_turns,
    carry_garment,
    fit_garment,
)
from gnngarment.geometry.normals import vertex_normals
from gnngarment.inference.checks import Z_UP_FROM_Y_UP, inside_fraction

REAL_WORLD = Path(__file__).resolve().parents[2].parent / "shared" / "real-world"


def _body(anny_body, preset: str) -> tuple[np.ndarray, np.ndarray]:
    rest = anny_body.rest(anny_body.parse_shape(preset))
    return rest.vertices.numpy().astype(np.float64), np.asarray(anny_body.faces)


def _median_distance(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> float:
    from gnngarment.inference.checks import _Surface

    return float(np.median(np.abs(_Surface(vertices, faces).signed_distance(points))))


def test_axis_turns_are_the_24_proper_axis_rotations():
    turns = axis_turns()
    assert len({t.tobytes() for t in turns}) == 24
    for turn in turns:
        assert np.allclose(turn @ turn.T, np.eye(3)) and np.isclose(np.linalg.det(turn), 1)


def test_alignment_recovers_units_up_axis_facing_and_origin(anny_body):
    """The rest body given back as an SMPL-style file: Y up, facing +Z, centimetres,
    feet at the origin. The alignment must undo exactly that."""
    vertices, faces = _body(anny_body, "average")
    y_up = vertices @ Z_UP_FROM_Y_UP          # inverse turn: Z up → Y up, −Y front → +Z
    source = 100.0 * (y_up - [0.0, y_up[:, 1].min(), 0.0])
    alignment = align_bodies(source, faces, vertices, faces)
    assert np.allclose(alignment.rotation, Z_UP_FROM_Y_UP)
    assert alignment.scale == pytest.approx(0.01, rel=0.01)
    assert np.abs(alignment.apply(source) - vertices).max() < 0.01
    # Two independent samplings of one surface are ~1 cm apart (4000 samples of ~1.7 m²):
    # that is the floor; the next best turn must be clearly worse.
    assert alignment.chamfer < 0.012
    assert alignment.runner_up > alignment.chamfer + 0.008


def test_fit_keeps_the_garment_offset_on_a_different_body(anny_body):
    """A shell 15 mm outside the torso of a heavy body, given in centimetres and Y up,
    fitted onto the average body: it must sit ~15 mm outside that body, not inside it
    and not at the heavy body's girth."""
    source_v, faces = _body(anny_body, "heavy_female")
    target_v, _ = _body(anny_body, "average")
    normals = vertex_normals(source_v, faces)
    torso = np.flatnonzero((source_v[:, 2] > -0.1) & (source_v[:, 2] < 0.35)
                           & (np.abs(source_v[:, 0]) < 0.2))
    keep = np.zeros(len(source_v), dtype=bool)
    keep[torso] = True
    garment_faces = faces[keep[faces].all(axis=1)]
    renumber = np.full(len(source_v), -1)
    renumber[torso] = np.arange(len(torso))
    garment = source_v[torso] + 0.015 * normals[torso]
    garment_faces = renumber[garment_faces]

    def as_file(points):
        return 100.0 * (points @ Z_UP_FROM_Y_UP)

    before = _median_distance(garment, target_v, faces)
    fitted = fit_garment(as_file(garment), garment_faces, as_file(source_v), faces, target_v,
                         faces)
    after = _median_distance(fitted.pos, target_v, faces)
    assert abs(after - 0.015) < 0.006, (before, after)
    assert inside_fraction(fitted.pos, target_v, faces) < 0.02
    assert fitted.registration_error < 0.01


def test_carry_garment_without_displacement_is_identity():
    rng = np.random.default_rng(0)
    body = rng.normal(size=(200, 3))
    garment = rng.normal(size=(50, 3))
    faces = np.array([[0, 1, 2], [2, 3, 4]])
    assert np.allclose(carry_garment(garment, faces, body, body), garment)


@pytest.mark.skipif(not REAL_WORLD.is_dir(), reason="../shared/real-world is absent (third-party "
                    "test data beside the repository, not in a clone)")
def test_real_smpl_garment_keeps_its_distance_to_the_body(anny_body):
    from gnngarment.geometry.mesh_io import load_mesh

    pos, faces = load_mesh(REAL_WORLD / "garments" / "ncs_tshirt.obj")
    source_v, source_f = load_mesh(REAL_WORLD / "bodies" / "ncs_smpl_female_neutral_body.obj")
    target_v, target_f = _body(anny_body, "average")
    fitted = fit_garment(pos, faces, source_v, source_f, target_v, target_f)
    # SMPL: Y up, facing +Z → ours: Z up, facing −Y.
    assert np.allclose(fitted.alignment.rotation, Z_UP_FROM_Y_UP)
    source_distance = _median_distance(pos, source_v.astype(np.float64), source_f)
    assert abs(_median_distance(fitted.pos, target_v, target_f) - source_distance) < 0.005
    assert inside_fraction(fitted.pos, target_v, target_f) < 0.02
