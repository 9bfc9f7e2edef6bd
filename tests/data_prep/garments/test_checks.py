"""The validators: `self_intersections` and `garment_problems`."""

from __future__ import annotations

import numpy as np

from data_prep.garments import BodyFrame, Garment, garment_problems, self_intersections


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


def _copy(garment: Garment) -> Garment:
    import dataclasses

    return dataclasses.replace(garment, pos=garment.pos.copy(), faces=garment.faces.copy())
