from __future__ import annotations

import pytest

from tests.training.criteria import sheets


@pytest.fixture
def sheet():
    return sheets.sheet()
