"""Checkpoints carry a content hash (checked on load) and the environment they were made in."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from gnngarment.model import GarmentDeformer
from gnngarment.model.checkpoint import (
    CHECKPOINT_FORMAT_VERSION,
    load_checkpoint,
    load_model,
    model_payload,
    release_checkpoint,
    save_checkpoint,
)
from tests.model.pairs import tiny_config


@pytest.fixture(scope="module")
def model() -> GarmentDeformer:
    torch.manual_seed(0)
    return GarmentDeformer(tiny_config())


def test_flipped_tensor_bytes_are_refused_naming_the_file(model: GarmentDeformer,
                                                           tmp_path: Path) -> None:
    path = tmp_path / "model.pt"
    save_checkpoint(path, model_payload(model))
    data = bytearray(path.read_bytes())
    # The raw bytes of one weight matrix (torch stores tensors uncompressed): flip 64 of
    # them in place, the damage a bad disk or copy does without breaking the zip.
    weight = next(t for t in model.state_dict().values() if t.numel() >= 64)
    start = bytes(data).find(weight.numpy().tobytes())
    assert start > 0
    data[start:start + 64] = bytes(b ^ 0xFF for b in data[start:start + 64])
    corrupt = tmp_path / "corrupt.pt"
    corrupt.write_bytes(bytes(data))
    for load in (load_checkpoint, load_model):
        with pytest.raises(ValueError, match=r"corrupt.pt is corrupt: content hash mismatch"
                           ) as raised:
            load(corrupt)
        assert "\n" not in str(raised.value)
    load_model(path)  # the intact file still loads


def test_checkpoint_without_a_hash_loads_unchecked_when_asked(model: GarmentDeformer,
                                                              tmp_path: Path) -> None:
    path = tmp_path / "old.pt"  # as saved before hashes were stored
    torch.save({"format_version": CHECKPOINT_FORMAT_VERSION, **model_payload(model)}, path)
    loaded = load_model(path, allow_unverified=True)
    for (name, a), b in zip(model.state_dict().items(), loaded.state_dict().values(),
                            strict=True):
        assert torch.equal(a, b), name


def test_every_checkpoint_records_threads_and_library_versions(model: GarmentDeformer,
                                                               tmp_path: Path) -> None:
    import torch_geometric

    path = tmp_path / "model.pt"
    save_checkpoint(path, model_payload(model))
    environment = load_checkpoint(path)["environment"]
    assert environment["torch_threads"] == torch.get_num_threads()
    assert environment["deterministic"] == torch.are_deterministic_algorithms_enabled()
    assert environment["torch"] == torch.__version__
    assert environment["numpy"] == np.__version__
    assert environment["torch_geometric"] == torch_geometric.__version__
    # A released model keeps the environment of the run that made it, under a valid hash.
    recorded = {**environment, "torch_threads": 7}
    save_checkpoint(path, {**model_payload(model), "environment": recorded})
    released = release_checkpoint(path, tmp_path / "released.pt")
    assert load_checkpoint(released)["environment"] == recorded


def test_a_release_can_set_a_reach_but_not_change_the_network(model: GarmentDeformer,
                                                               tmp_path: Path) -> None:
    """Settings that need no retraining are applied and recorded; an invalid one or one
    that changes the weights' shapes is refused before anything is written."""
    path = tmp_path / "model.pt"
    save_checkpoint(path, model_payload(GarmentDeformer(tiny_config(weight_reach=None))))
    released = release_checkpoint(path, tmp_path / "released.pt", {"weight_reach": 0.15})
    assert load_model(released).config.weight_reach == 0.15
    assert load_checkpoint(released)["release_settings"] == {"weight_reach": 0.15}
    assert load_model(path).config.weight_reach is None
    for settings, message in (({"weight_reach": -1.0}, "weight_reach must be positive"),
                              ({"processor_channels": 8}, "does not fit its weights")):
        with pytest.raises(ValueError, match=message):
            release_checkpoint(path, tmp_path / "refused.pt", settings)
    assert not (tmp_path / "refused.pt").exists()


def _tiny_checkpoint(path):
    from gnngarment.model import GarmentDeformer
    from gnngarment.model.checkpoint import model_payload, save_checkpoint
    from tests.model.pairs import tiny_config

    torch.manual_seed(0)
    save_checkpoint(path, model_payload(GarmentDeformer(tiny_config())))
    return path


def test_a_checkpoint_without_its_hash_loads_only_when_asked(tmp_path) -> None:
    """Issue 38: deleting the hash key let a tampered checkpoint (weights x 1000) load
    unchecked as 'legacy'."""
    from gnngarment.model.checkpoint import (
        CONTENT_HASH_KEY,
        load_checkpoint,
        load_model,
        rehash_checkpoint,
    )

    path = _tiny_checkpoint(tmp_path / "model.pt")
    payload = torch.load(path, weights_only=True)
    del payload[CONTENT_HASH_KEY]
    name = next(iter(payload["model_state"]))
    payload["model_state"][name] = payload["model_state"][name] * 1000
    torch.save(payload, path)
    with pytest.raises(ValueError, match="no content hash.*--allow-unverified"):
        load_model(path)
    assert load_model(path, allow_unverified=True) is not None
    rehash_checkpoint(path)
    assert CONTENT_HASH_KEY in load_checkpoint(path)


@pytest.mark.parametrize("change, message", [
    ("a string", "model_config is a str"),
    ({"garment_channels": [8, 200_000, 200_000]}, "garment_channels"),
    ({"body_vertices": 10**7}, "body_vertices"),
    ({"window": 10**6}, "window"),
])
def test_a_checkpoint_config_is_validated_before_anything_is_built(tmp_path, change,
                                                                   message) -> None:
    """A config that is not a mapping, or that asks for absurd sizes, is refused by name
    before a tensor is allocated (200,000 channels ran this machine out of memory)."""
    from gnngarment.model.checkpoint import load_model, save_checkpoint

    path = _tiny_checkpoint(tmp_path / "model.pt")
    payload = torch.load(path, weights_only=True)
    payload["model_config"] = change if isinstance(change, str) else {
        **payload["model_config"], **change}
    save_checkpoint(path, payload)
    with pytest.raises(ValueError, match=message):
        load_model(path)
