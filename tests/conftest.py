"""Shared fixtures: Anny is constructed once per test session (its first construction on
a fresh machine builds a ~1.5 min cache; later ones take ~0.5 s)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def anny_body():
    from gnngarment.body.anny_model import AnnyBodyModel

    return AnnyBodyModel()


@pytest.fixture(scope="session")
def anny_rest(anny_body):
    return anny_body.rest()
