"""The RNG states a training checkpoint carries for an exact resume (saved and restored
by :class:`~gnngarment.training.trainer.Trainer`; the checkpoint format itself is
:mod:`gnngarment.model.checkpoint`)."""

from __future__ import annotations

import random
from typing import Any

import numpy as np
import torch


def rng_state() -> dict[str, Any]:
    """torch, numpy-global and python RNG states as plain tensors/lists (safe to load
    with ``weights_only``)."""
    numpy_state = np.random.get_state()
    return {"torch": torch.get_rng_state(),
            "numpy": [numpy_state[0], torch.from_numpy(numpy_state[1].astype(np.int64)),
                      *numpy_state[2:]],
            "python": [random.getstate()[0], list(random.getstate()[1]), random.getstate()[2]]}


def set_rng_state(state: dict[str, Any]) -> None:
    torch.set_rng_state(state["torch"])
    kind, keys, position, has_gauss, cached = state["numpy"]
    np.random.set_state((kind, keys.numpy().astype(np.uint32), position, has_gauss, cached))
    version, internal, gauss = state["python"]
    random.setstate((version, tuple(internal), gauss))
