"""Shared fixtures: a small tube garment and tiny deformers, with the two 50-point
attributions most tests look at computed once per session."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
import torch

from gnngarment.attribution import Attribution, attribute
from gnngarment.data.pair import GarmentBodyPair
from gnngarment.model import GarmentDeformer, ModelConfig
from gnngarment.threads import one_thread
from tests.meshes import tube
from tests.model.pairs import frame_inputs, make_pair, tiny_config

#: A vertex of the middle ring (9 of 18) of the 8-section tube.
TARGET = 9 * 8 + 3


def attribution_config(levels: int) -> ModelConfig:
    """tiny_config, narrower (F = 8) so that 50-point integrated gradients stay fast."""
    return tiny_config(garment_channels=[4, 8, 8], style_channels=[16, 8],
                       body_channels=[16, 8], motion_hidden=8, processor_channels=8,
                       levels=levels)


def build(levels: int, seed: int = 0) -> GarmentDeformer:
    torch.manual_seed(seed)
    return GarmentDeformer(attribution_config(levels)).eval()


@pytest.fixture(autouse=True)
def _one_thread() -> Iterator[None]:
    """Graphs of ~150 vertices are too small to gain from intra-op threads, and on a
    shared CPU the threads thrash (measured 3-8× slower)."""
    with one_thread():
        yield


@pytest.fixture(scope="session")
def garment() -> tuple[np.ndarray, np.ndarray]:
    """An 18-ring × 8-section open tube (144 vertices, 0.6 m tall, 0.3 m radius)."""
    return tube(18, 8)


@pytest.fixture(scope="session")
def pair(garment) -> GarmentBodyPair:
    return make_pair(*garment, attribution_config(2), levels=2)


@pytest.fixture(scope="session")
def frame():
    return frame_inputs(attribution_config(2), 1, 1, seed=3)


@pytest.fixture(scope="session")
def single_level(pair, frame) -> tuple[GarmentDeformer, Attribution]:
    model = build(levels=0)
    with one_thread():
        return model, attribute(model, pair, frame, target="vertex", target_vertices=TARGET)


@pytest.fixture(scope="session")
def multilevel(pair, frame) -> tuple[GarmentDeformer, Attribution]:
    model = build(levels=2)
    with one_thread():
        return model, attribute(model, pair, frame, target="vertex", target_vertices=TARGET)
