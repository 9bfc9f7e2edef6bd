"""`Sections` and `Stack`: a stack solid is a body's sections made solid."""

from __future__ import annotations

import numpy as np

from data_prep.garments.shapes import Sections, Stack


def test_a_stack_is_sections_with_caps() -> None:
    z = np.array([0.0, 0.5, 1.0])
    ones = np.ones(3)
    stack = Stack(z=z, cx=np.zeros(3), cy=np.zeros(3), a=0.2 * ones, bf=0.1 * ones,
                  bb=0.1 * ones, p=2 * ones, bottom=0.0)
    assert isinstance(stack, Sections)
    assert stack.at(0.25)["a"] == 0.2
    upper = stack.between(0.4, 1.0)
    assert type(upper) is Sections  # the caps are not per height: plain sections
    np.testing.assert_array_equal(upper.z, [0.5, 1.0])
    assert stack(np.array([[0.0, 0.0, 0.5], [0.5, 0.0, 0.5]]))[0] < 0 < stack(
        np.array([[0.5, 0.0, 0.5]]))[0]
