from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import pytest

from gnngarment.config import ConfigError
from gnngarment.paths import REPOSITORY_ROOT, default_config
from gnngarment.training.config import TrainingConfig
from gnngarment.training.loading import load_training_config


def test_paper_config_equals_the_dataclass_defaults() -> None:
    assert asdict(load_training_config(default_config("train/paper.yaml"))) == asdict(
        TrainingConfig())


def test_model_file_training_overrides_and_command_line(tmp_path: Path) -> None:
    path = tmp_path / "run.yaml"
    path.write_text("model_config: configs/model/small.yaml\nmodel: {levels: 1}\nepochs: 7\n")
    config = load_training_config(path, ["pairs_per_batch=2", "model.pooling=topk"])
    assert config.epochs == 7 and config.pairs_per_batch == 2
    assert config.model.levels == 1 and config.model.pooling == "topk"
    assert config.model.garment_channels == [8, 16, 16]  # from small.yaml


@pytest.mark.parametrize("text,overrides,message", [
    ("epohcs: 3\n", [], "epohcs"),
    ("model_config: absent.yaml\n", [], "absent.yaml"),
    ("epochs: 3\n", ["modle.levels=1"], "modle"),
    ("model: {pooling: mean}\n", [], "pooling"),
    ("epochs: 0\n", [], "bad.yaml: key 'epochs': must be >= 1, got 0"),
    ("learning_rate: .nan\n", [], "key 'learning_rate': must be a finite number > 0"),
    ("epochs: 3\n", ["pairs_per_batch=0"], "key 'pairs_per_batch': must be >= 1"),
    ("seed: -1\n", [], "key 'seed': must be >= 0"),
    ("losses: {collision: -1.5}\n", [], "key 'losses.collision'"),
    ("stages: {max_epochs: [4, 1]}\n", [], "key 'stages.max_epochs': expected 3"),
    ("stages: {collision_window: 0}\n", [], "key 'stages.collision_window'"),
])
def test_bad_configs_are_named(tmp_path: Path, text: str, overrides, message: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises((ConfigError, ValueError), match=message):
        load_training_config(path, overrides)


@pytest.mark.parametrize("override", ["initial_weights=null", "initial_weights="])
def test_a_fine_tune_config_can_start_from_scratch(override: str) -> None:
    """``--set initial_weights=null`` turns a config that names starting weights into a
    run from a fresh initialisation (no edited copy of the file needed)."""
    config = REPOSITORY_ROOT / "configs/train/cmu_dynamics.yaml"
    assert load_training_config(config).initial_weights
    assert not load_training_config(config, [override]).initial_weights
