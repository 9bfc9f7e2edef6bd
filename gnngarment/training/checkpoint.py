"""Checkpoints: written atomically, loaded with ``weights_only=True``."""

from __future__ import annotations

import random
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import torch

from gnngarment.config import merge_config
from gnngarment.geometry.files import atomic_write
from gnngarment.model.config import ModelConfig
from gnngarment.model.deformer import GarmentDeformer

CHECKPOINT_FORMAT_VERSION = 1


def save_checkpoint(path: str | Path, payload: dict[str, Any]) -> None:
    """``torch.save`` to a temp file in the same folder, then rename: a kill -9 during
    the write leaves the previous checkpoint intact."""
    atomic_write(path, lambda stream: torch.save(
        {"format_version": CHECKPOINT_FORMAT_VERSION, **payload}, stream))


def load_checkpoint(path: str | Path) -> dict[str, Any]:
    """Load a checkpoint safely (no pickled code: ``weights_only=True``).

    Raises:
        ValueError: missing, truncated or foreign file (names it).
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: checkpoint not found")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as error:  # truncated zip, unpickling refusal, ...
        raise ValueError(f"{path}: not a readable gnngarment checkpoint ({error})") from error
    if not isinstance(payload, dict) or payload.get("format_version") != CHECKPOINT_FORMAT_VERSION:
        raise ValueError(f"{path}: not a gnngarment checkpoint (format "
                         f"{payload.get('format_version') if isinstance(payload, dict) else '?'})")
    return payload


def model_payload(model: GarmentDeformer) -> dict[str, Any]:
    """What a checkpoint needs to rebuild the model: its config and weights."""
    return {"model_config": asdict(model.config), "model_state": model.state_dict(),
            "use_physics": model.use_physics}


#: Settings added to :class:`ModelConfig` after checkpoints were first saved, with the
#: value that reproduces the models saved without them (not the current default).
LEGACY_MODEL_SETTINGS = {"weight_prior": "none"}


def stored_model_config(stored: dict[str, Any], source: str = "<checkpoint>") -> ModelConfig:
    """The :class:`ModelConfig` of a checkpoint's ``model_config`` dict; settings it
    predates take their :data:`LEGACY_MODEL_SETTINGS` value, so old models keep their
    behaviour.

    Raises:
        ConfigError: unknown key or wrong type (names ``source``).
    """
    return merge_config(ModelConfig, {**LEGACY_MODEL_SETTINGS, **stored}, source=source)


def load_model(path: str | Path) -> GarmentDeformer:
    """Rebuild a model from a checkpoint, in eval mode."""
    payload = load_checkpoint(path)
    config = stored_model_config(payload["model_config"], source=str(path))
    model = GarmentDeformer(config)
    model.load_state_dict(payload["model_state"])
    model.use_physics = bool(payload.get("use_physics", False))
    model.eval()
    return model


#: What a released (shipped) checkpoint keeps: enough to rebuild the model and to say how
#: it was made; the optimiser, scheduler and RNG states only matter for resuming.
RELEASE_KEYS = ("model_config", "model_state", "use_physics", "epoch", "schedule",
                "training_config", "data_manifest_hash", "history")


def release_checkpoint(source: str | Path, destination: str | Path) -> Path:
    """Write ``source`` without its training-only state (optimiser, scheduler, RNG) to
    ``destination`` (atomically): a training run's ``last.pt`` → a model to ship.

    Raises:
        ValueError: ``source`` is not a readable checkpoint (names it).
    """
    payload = load_checkpoint(source)
    save_checkpoint(destination, {k: payload[k] for k in RELEASE_KEYS if k in payload})
    return Path(destination)


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
