"""The fabric presets and `resolve_fabric` (no Newton run)."""

from __future__ import annotations

import dataclasses
import itertools

import pytest

from data_prep.simulate import FABRICS, FabricPreset, resolve_fabric


def test_presets_are_named_like_cloth3d_and_ordered_by_stiffness() -> None:
    assert set(FABRICS) == {"cotton", "silk", "denim", "leather"}
    order = [FABRICS[name] for name in ("silk", "cotton", "denim", "leather")]
    for lighter, stiffer in itertools.pairwise(order):
        assert lighter.stretch_stiffness < stiffer.stretch_stiffness
        assert lighter.bend_stiffness < stiffer.bend_stiffness
    assert resolve_fabric(" Denim ") is FABRICS["denim"]
    assert resolve_fabric(FABRICS["silk"]) is FABRICS["silk"]


def test_unknown_or_invalid_fabric_is_rejected() -> None:
    with pytest.raises(ValueError, match="unknown fabric 'tweed'.*cotton"):
        resolve_fabric("tweed")
    with pytest.raises(ValueError, match="density"):
        dataclasses.replace(FABRICS["cotton"], density=-1.0)
    with pytest.raises(ValueError, match="friction"):
        FabricPreset("x", 0.2, 1e4, 1e4, 1e-5, 0.0, float("nan"))
