"""`pair` and `resample`: front and back outlines become one pattern."""

from __future__ import annotations

import numpy as np
import pytest

from data_prep.garments.errors import PatternError
from data_prep.garments.panel_boundary import PanelBoundary
from data_prep.garments.pattern import pair, resample


def square_boundary(shift: int = 0, wobble: float = 0.0) -> PanelBoundary:
    """A unit square, counter-clockwise: a seam up the right side, an opening (label 1)
    along the top, a seam down the left and along the bottom; runs rotated by ``shift``."""
    runs = [np.array([[1.0, 0.0], [1.0, 0.5], [1.0, 1.0]]),
            np.array([[1.0, 1.0], [0.5, 1.0 + wobble], [0.0, 1.0]]),
            np.array([[0.0, 1.0], [0.0, 0.0], [1.0, 0.0]])]
    labels = [0, 1, 0]
    return PanelBoundary(runs=runs[shift:] + runs[:shift], labels=labels[shift:] + labels[:shift])


def test_pair_shares_the_front_seams_and_snaps_the_back_openings() -> None:
    front = square_boundary()
    back = square_boundary(shift=1, wobble=0.1)  # a deeper opening, listed from another run
    back.runs[0][0] += 0.01  # the back's corner is a little off
    pattern = pair(front, back)
    assert pattern.order == [(0, 0), (1, 0), (0, 1)]
    for mine, theirs in zip(pattern.seams, [front.runs[0], front.runs[2]], strict=True):
        np.testing.assert_array_equal(mine, theirs)
    back_opening = pattern.openings[1][0]
    np.testing.assert_array_equal(back_opening[[0, -1]], [[1.0, 1.0], [0.0, 1.0]])
    assert back_opening[1, 1] == pytest.approx(1.1)
    for side in (-1, 1):  # each panel's runs join end to start
        runs = pattern.boundary(side)
        for run, following in zip(runs, runs[1:] + runs[:1], strict=True):
            np.testing.assert_array_equal(run[-1], following[0])


def test_pair_rejects_panels_with_different_openings() -> None:
    back = square_boundary()
    back.labels[1] = 2
    with pytest.raises(PatternError, match="different openings"):
        pair(square_boundary(), back)


def test_resample_spaces_points_evenly_in_the_given_lengths() -> None:
    polyline = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    points = resample(polyline, np.array([1.0, 3.0]), spacing=1.0)  # second leg counts 3×
    assert len(points) == 5
    np.testing.assert_allclose(points, [[0, 0], [1, 0], [1, 1 / 3], [1, 2 / 3], [1, 1]])
