"""`styled_upper_parts` and `shirt_torso`: the style-driven wrappers of the parts."""

from __future__ import annotations

import pytest

from data_prep.garments import BodyFrame, DressStyle, SkirtStyle
from data_prep.garments.parts import UPPER_SETTINGS, shirt_torso, styled_upper_parts, upper_parts


def test_styled_upper_parts_reads_the_style_fields(body: BodyFrame) -> None:
    m = body.measurements
    _, torso = shirt_torso(m, body.vertices, 0.5, 0.03)
    style = DressStyle(sleeves="sleeved")
    settings = {name: getattr(style, name) for name in UPPER_SETTINGS if name != "sleeve_flare"}
    solids, cuts, loops, top = styled_upper_parts(body.vertices, m, torso, style,
                                                  sleeve_flare=0.0)
    expected = upper_parts(body.vertices, m, torso, sleeve_flare=0.0, **settings)
    assert [cut.name for cut in cuts] == [cut.name for cut in expected[1]]
    assert repr(cuts) == repr(expected[1])  # the same cuts, value for value
    assert (len(solids), loops, top) == (len(expected[0]), expected[2], expected[3])


def test_styled_upper_parts_needs_every_setting(body: BodyFrame) -> None:
    m = body.measurements
    _, torso = shirt_torso(m, body.vertices, 0.5, 0.03)
    with pytest.raises(AttributeError, match="sleeves"):
        styled_upper_parts(body.vertices, m, torso, SkirtStyle())


def test_shirt_torso_hem_runs_from_the_waist_to_below_the_crotch(body: BodyFrame) -> None:
    m = body.measurements
    assert shirt_torso(m, body.vertices, 0.0, 0.03)[0] == pytest.approx(m.z_waist)
    assert shirt_torso(m, body.vertices, 1.0, 0.03)[0] == pytest.approx(m.z_crotch - 0.12)
