"""`measure_body` on the synthetic body: part labels, heights, sections, armpits."""

from __future__ import annotations

import numpy as np

from data_prep.garments import BodyFrame
from data_prep.garments.measurements import ARM_L, ARM_R, HEAD, TRUNK


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
