"""The checkpoint format and model loading: written atomically with a content hash,
loaded with ``weights_only=True`` and checked against the hash; a model rebuilt from one.

What a checkpoint carries only to resume a training run (optimiser, scheduler and RNG
states) is written and read by the trainer."""

from __future__ import annotations

import hashlib
import re
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import torch

from gnngarment.config import merge_config
from gnngarment.io.atomic import atomic_write
from gnngarment.model.config import ModelConfig
from gnngarment.model.deformer import GarmentDeformer

CHECKPOINT_FORMAT_VERSION = 1
#: Key of the payload's sha256 (:func:`content_hash`); checkpoints saved before it have none.
CONTENT_HASH_KEY = "content_hash"
#: Key of the :func:`runtime_environment` a checkpoint was made in.
ENVIRONMENT_KEY = "environment"


def _hash_value(digest: Any, value: Any) -> None:
    """Feed ``value`` into ``digest`` in an order that does not depend on dict insertion
    order; tensors contribute dtype, shape and raw bytes."""
    if isinstance(value, torch.Tensor):
        tensor = value.detach().cpu().contiguous()
        digest.update(f"tensor {tensor.dtype} {tuple(tensor.shape)};".encode())
        digest.update(tensor.reshape(-1).view(torch.uint8).numpy().tobytes())
    elif isinstance(value, dict):
        digest.update(f"dict {len(value)};".encode())
        for key in sorted(value, key=repr):
            digest.update(f"{key!r}:".encode())
            _hash_value(digest, value[key])
    elif isinstance(value, (list, tuple)):  # torch.load may turn one into the other
        digest.update(f"list {len(value)};".encode())
        for item in value:
            _hash_value(digest, item)
    else:  # str, int, float, bool, None: repr is exact (floats round-trip)
        digest.update(f"{type(value).__name__} {value!r};".encode())


def content_hash(payload: dict[str, Any]) -> str:
    """sha256 (hex) of a checkpoint payload: every tensor's bytes and every other value,
    keys in sorted order, the stored hash itself left out."""
    digest = hashlib.sha256()
    _hash_value(digest, {k: v for k, v in payload.items() if k != CONTENT_HASH_KEY})
    return digest.hexdigest()


def runtime_environment() -> dict[str, Any]:
    """What a run's numbers depend on besides its config and seed: torch's thread
    counts, whether its deterministic algorithms were on, and the versions of python,
    torch, numpy, torch_geometric and gnngarment (``None`` for one not installed)."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    def installed(name: str) -> str | None:
        try:
            return version(name)
        except PackageNotFoundError:
            return None

    return {"torch_threads": torch.get_num_threads(),
            "torch_interop_threads": torch.get_num_interop_threads(),
            "deterministic": torch.are_deterministic_algorithms_enabled(),
            "python": platform.python_version(), "torch": str(torch.__version__),
            "numpy": str(np.__version__), "torch_geometric": installed("torch_geometric"),
            "gnngarment": installed("gnngarment")}


def save_checkpoint(path: str | Path, payload: dict[str, Any]) -> None:
    """``torch.save`` to a temp file in the same folder, then rename: a kill -9 during
    the write leaves the previous checkpoint intact.

    Adds ``format_version``, the :func:`runtime_environment` (unless ``payload`` carries
    one already, as a released checkpoint keeps its training run's) and the
    :func:`content_hash` that :func:`load_checkpoint` checks.
    """
    payload = {"format_version": CHECKPOINT_FORMAT_VERSION,
               ENVIRONMENT_KEY: runtime_environment(),
               **{k: v for k, v in payload.items() if k != CONTENT_HASH_KEY}}
    payload[CONTENT_HASH_KEY] = content_hash(payload)
    atomic_write(path, lambda stream: torch.save(payload, stream))


#: How to give an old checkpoint a content hash (docs/reliability.md).
REHASH_HINT = ("python -c \"from gnngarment.model.checkpoint import rehash_checkpoint; "
               "rehash_checkpoint('<file>')\"")


def load_checkpoint(path: str | Path, allow_unverified: bool = False) -> dict[str, Any]:
    """Load a checkpoint safely (no pickled code: ``weights_only=True``) and check its
    content hash. One without a ``content_hash`` key (saved before hashes were stored,
    or with the key removed: a change to it cannot be detected) is refused unless
    ``allow_unverified`` (``--allow-unverified``); :func:`rehash_checkpoint` gives a
    trusted one a hash.

    Raises:
        ValueError: missing, truncated, corrupt (content hash mismatch) or foreign file
            (names it).
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: checkpoint not found")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as error:  # truncated zip, unpickling refusal, ...
        lines = [line.strip() for line in str(error).splitlines() if line.strip()]
        if lines and lines[0].startswith("Weights only load failed"):
            # torch's message spans many lines; its gist is the last one before the link.
            lines = [line for line in lines if not line.startswith("Check the documentation")]
            gist = lines[-1].removeprefix("WeightsUnpickler error:").strip().split(". ")[0]
            detail = f"refused by weights-only loading: {gist}"
        else:  # its first sentence: torch adds a paragraph of advice to a truncated zip's
            detail = (re.split(r"(?<=\.)\s+(?=[A-Z])", lines[0])[0].rstrip(".") if lines
                      else type(error).__name__)
        raise ValueError(f"{path}: not a readable gnngarment checkpoint ({detail})") from error
    if not isinstance(payload, dict) or payload.get("format_version") != CHECKPOINT_FORMAT_VERSION:
        raise ValueError(f"{path}: not a gnngarment checkpoint (format "
                         f"{payload.get('format_version') if isinstance(payload, dict) else '?'})")
    stored = payload.get(CONTENT_HASH_KEY)
    if stored is None and not allow_unverified:
        raise ValueError(f"{path}: has no content hash, so a change to it cannot be "
                         "detected; load it only if you trust its source "
                         f"(--allow-unverified), or re-hash it once: {REHASH_HINT}")
    if stored is not None and stored != content_hash(payload):
        raise ValueError(f"{path} is corrupt: content hash mismatch (its contents changed "
                         "after it was saved; use another copy)")
    return payload


def rehash_checkpoint(path: str | Path) -> Path:
    """Give a trusted checkpoint without a content hash one (rewritten atomically), so it
    loads without ``--allow-unverified``. Only for a file whose source you trust: the hash
    then certifies its present contents."""
    save_checkpoint(path, load_checkpoint(path, allow_unverified=True))
    return Path(path)


def model_payload(model: GarmentDeformer) -> dict[str, Any]:
    """What a checkpoint needs to rebuild the model: its config and weights."""
    return {"model_config": asdict(model.config), "model_state": model.state_dict(),
            "use_physics": model.use_physics}


#: Settings added to :class:`ModelConfig` after checkpoints were first saved, with the
#: value that reproduces the models saved without them (not the current default).
LEGACY_MODEL_SETTINGS = {"weight_prior": "none", "weight_reach": None, "motion_reach": False}


def stored_model_config(stored: dict[str, Any], source: str = "<checkpoint>") -> ModelConfig:
    """The :class:`ModelConfig` of a checkpoint's ``model_config`` dict; settings it
    predates take their :data:`LEGACY_MODEL_SETTINGS` value, so old models keep their
    behaviour.

    Raises:
        ConfigError: unknown key or wrong type (names ``source``).
    """
    return merge_config(ModelConfig, {**LEGACY_MODEL_SETTINGS, **stored}, source=source)


def model_with_weights(config: ModelConfig, state: dict[str, Any], mismatch: str
                       ) -> GarmentDeformer:
    """A :class:`GarmentDeformer` built from ``config`` holding the weights ``state``.

    Raises:
        ValueError: the weights do not fit: ``mismatch`` followed by torch's first line.
    """
    model = GarmentDeformer(config)
    try:
        model.load_state_dict(state)
    except (RuntimeError, KeyError, TypeError) as error:
        # torch lists every mismatched key over many lines: one line names the first.
        first = str(error).replace("\n", " ").split(". ")[0]
        raise ValueError(f"{mismatch}: {first[:200]}") from None
    return model


def load_model(path: str | Path, allow_unverified: bool = False) -> GarmentDeformer:
    """Rebuild a model from a checkpoint, in eval mode (``allow_unverified``: see
    :func:`load_checkpoint`). Its config is validated (types and ranges, like a YAML
    model config) before anything is built.

    Raises:
        ValueError: unreadable, or its weights do not fit its model config (names it).
    """
    payload = load_checkpoint(path, allow_unverified)
    # A training-state file or a foreign torch file of the same format: no model in it.
    missing = [key for key in ("model_config", "model_state") if key not in payload]
    if missing:
        raise ValueError(f"{path}: not a model checkpoint (no {' or '.join(missing)})")
    if not isinstance(payload["model_config"], dict):
        raise ValueError(f"{path}: model_config is a {type(payload['model_config']).__name__}, "
                         "expected a mapping of settings")
    config = stored_model_config(payload["model_config"], source=str(path))
    model = model_with_weights(config, payload["model_state"],
                               f"{path}: the weights do not fit the model its config "
                               "describes (another architecture or a damaged checkpoint)")
    model.use_physics = bool(payload.get("use_physics", False))
    model.eval()
    return model


#: What a released (shipped) checkpoint keeps: enough to rebuild the model and to say how
#: it was made; the optimiser, scheduler and RNG states only matter for resuming.
RELEASE_KEYS = ("model_config", "model_state", "use_physics", "epoch", "schedule",
                "training_config", "data_manifest_hash", "history", ENVIRONMENT_KEY,
                "release_settings")


def release_checkpoint(source: str | Path, destination: str | Path,
                       model_settings: dict[str, Any] | None = None) -> Path:
    """Write ``source`` without its training-only state (optimiser, scheduler, RNG) to
    ``destination`` (atomically): a training run's ``last.pt`` → a model to ship.

    ``model_settings`` changes model-config values that need no retraining (e.g.
    ``{"weight_reach": 0.2}``, which only masks the weight head); they are recorded under
    ``release_settings`` so the checkpoint says its config is not the one it trained with.

    Raises:
        ValueError: ``source`` is not a readable checkpoint (names it), or a setting
            is unknown, invalid, or changes the weights' shapes.
    """
    payload = load_checkpoint(source)
    released = {k: payload[k] for k in RELEASE_KEYS if k in payload}
    if model_settings:
        config = stored_model_config({**released["model_config"], **model_settings},
                                     source=f"{source} + {model_settings}")
        model_with_weights(config, released["model_state"],
                           f"{source}: {model_settings} does not fit its weights")
        released["model_config"] = asdict(config)
        released["release_settings"] = {**released.get("release_settings", {}),
                                         **model_settings}
    save_checkpoint(destination, released)
    return Path(destination)
