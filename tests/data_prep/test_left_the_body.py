"""A garment that slid off or fell down the body is caught; one that moves with the body
is not."""

from __future__ import annotations

import numpy as np

from data_prep.left_the_body import left_the_body


def down(metres: float) -> np.ndarray:
    return np.array([0.0, 0.0, -metres])


def test_a_garment_that_slides_down_the_body_is_caught() -> None:
    rng = np.random.default_rng(0)
    body = rng.uniform([-0.2, -0.1, -0.9], [0.2, 0.1, 0.7], size=(500, 3))
    rest = rng.uniform([-0.2, -0.12, -0.3], [0.2, 0.12, 0.1], size=(200, 3))
    worn = np.stack([rest, rest + down(0.05)])               # a little sag: fine
    assert left_the_body(worn, np.stack([body, body]), rest=rest) == ""
    fallen = np.stack([rest, rest + down(0.5)])              # slid to the shins
    assert "fell down" in left_the_body(fallen, np.stack([body, body]), rest=rest)
    assert left_the_body(fallen, np.stack([body, body])) == ""  # still near the body
    # The body squats by 0.4 m and the garment goes with it: not a fall.
    squat = np.stack([body, body + down(0.4)])
    assert left_the_body(np.stack([rest, rest + down(0.4)]), squat, rest=rest) == ""
