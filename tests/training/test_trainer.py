"""A tiny model through both stages, checkpoints and exact resume."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import torch

from gnngarment.data import PreparedDataset
from gnngarment.model.checkpoint import load_checkpoint, load_model, release_checkpoint
from gnngarment.training.config import StageConfig, TrainingConfig
from gnngarment.training.trainer import RunFolderError, Trainer, TrainingStep
from tests.model.pairs import tiny_config
from tests.synthetic_cache import build_synthetic_cache


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_synthetic_cache(tmp_path_factory.mktemp("cache"), frames=6)


def config_for(cache: Path, output: Path, epochs: int = 4) -> TrainingConfig:
    return TrainingConfig(
        data=str(cache), output=str(output), model=tiny_config(), epochs=epochs,
        pairs_per_batch=2, frames_per_pair=3, learning_rate=3e-3, threads=1,
        stages=StageConfig(supervised_window=5, collision_window=5, strain_window=5,
                           max_epochs=[2, 1, 0]))


def make_trainer(config: TrainingConfig, validation: bool = True) -> Trainer:
    window = config.model.window
    train = PreparedDataset(config.data, "train", window)
    val = PreparedDataset(config.data, "val", window) if validation else None
    return Trainer(config, train, val, progress=False)


def test_trains_through_both_stages_and_logs_the_switches(cache: Path, tmp_path: Path) -> None:
    config = config_for(cache, tmp_path / "run", epochs=4)
    trainer = make_trainer(config)
    physics_before = {n: p.clone() for n, p in trainer.model.named_parameters()}
    summary = trainer.fit()

    assert [s["to"] for s in summary["switches"]] == ["physics", "physics_strain"]
    assert all("epoch limit" in s["reason"] for s in summary["switches"])
    lines = [json.loads(x) for x in (tmp_path / "run" / "metrics.jsonl").read_text().splitlines()]
    assert [line["stage"] for line in lines] == ["supervised", "supervised", "physics",
                                                 "physics_strain"]
    assert lines[0]["vertex"] > lines[1]["vertex"]  # stage 1 learns
    assert {"collision", "gravity"} <= set(lines[2]) and "stretch" in lines[3]
    assert "val_vertex_error_mm" in lines[0]
    assert list((tmp_path / "run" / "tensorboard").iterdir())
    # Stage 2 trained only the physics submodule.
    after = dict(trainer.model.named_parameters())
    assert not torch.equal(after["physics_processor.output.lin.weight"],
                           physics_before["physics_processor.output.lin.weight"])
    model = load_model(tmp_path / "run" / "last.pt")
    assert model.use_physics


def test_resume_continues_exactly(cache: Path, tmp_path: Path) -> None:
    straight = make_trainer(config_for(cache, tmp_path / "straight"), validation=False)
    straight.fit()

    interrupted = make_trainer(config_for(cache, tmp_path / "resumed"), validation=False)
    interrupted.fit(stop_after=3)  # crosses the stage switch, then "dies"
    resumed = make_trainer(config_for(cache, tmp_path / "resumed"), validation=False)
    resumed.fit(resume=True)

    assert resumed.epoch == straight.epoch == 4
    for (name, a), b in zip(straight.model.state_dict().items(),
                            resumed.model.state_dict().values(), strict=True):
        assert torch.equal(a, b), name
    assert resumed.stages.state_dict() == straight.stages.state_dict()


def test_two_runs_with_two_threads_are_bitwise_equal(cache: Path, tmp_path: Path) -> None:
    """The default ``deterministic: true`` makes the thread count irrelevant to the
    result: two 2-thread runs of one config end with the same bits (without it the
    scatter sums of the graph layers differ in the last bits, ~3e-8 after two epochs of
    this tiny run, 7e-2 after a real one)."""
    from dataclasses import replace

    threads = torch.get_num_threads()
    try:
        weights = []
        for run in ("a", "b"):
            config = replace(config_for(cache, tmp_path / run, epochs=2), threads=2)
            trainer = make_trainer(config, validation=False)
            trainer.fit()
            weights.append(trainer.model.state_dict())
    finally:
        torch.set_num_threads(threads)
    assert torch.are_deterministic_algorithms_enabled()
    for name, value in weights[0].items():
        assert torch.equal(value, weights[1][name]), name


def test_a_run_folder_holds_one_run_and_its_metrics(cache: Path, tmp_path: Path) -> None:
    config = config_for(cache, tmp_path / "run", epochs=2)
    make_trainer(config, validation=False).fit()
    with pytest.raises(RunFolderError, match="last.pt: the output folder holds another run"):
        make_trainer(config, validation=False).fit()  # would have appended to its metrics
    metrics = tmp_path / "run" / "metrics.jsonl"
    # A kill after an epoch's log line but before its checkpoint, then one cut short.
    lines = metrics.read_text().splitlines()
    metrics.write_text("\n".join([*lines, lines[-1].replace('"epoch": 2', '"epoch": 3'),
                                  '{"epo']) + "\n")
    config.epochs = 3
    make_trainer(config, validation=False).fit(resume=True)
    assert [json.loads(line)["epoch"] for line in metrics.read_text().splitlines()] == [1, 2, 3]


def test_checkpoints_are_safe_and_bad_ones_are_named(cache: Path, tmp_path: Path) -> None:
    config = config_for(cache, tmp_path / "run", epochs=1)
    make_trainer(config, validation=False).fit()
    path = tmp_path / "run" / "last.pt"
    assert load_checkpoint(path)["epoch"] == 1
    truncated = tmp_path / "truncated.pt"
    truncated.write_bytes(path.read_bytes()[:1000])
    with pytest.raises(ValueError, match="truncated.pt: not a readable"):
        load_checkpoint(truncated)
    with pytest.raises(ValueError, match="absent.pt: checkpoint not found"):
        load_checkpoint(tmp_path / "absent.pt")
    assert [p.name for p in path.parent.iterdir() if p.suffix == ".tmp"] == []


def test_released_checkpoint_drops_training_state_and_predicts_the_same(
        cache: Path, tmp_path: Path) -> None:
    config = config_for(cache, tmp_path / "run", epochs=1)
    trainer = make_trainer(config, validation=False)
    trainer.fit()
    released = release_checkpoint(tmp_path / "run" / "last.pt", tmp_path / "model.pt")
    payload = load_checkpoint(released)
    assert not {"optimiser", "scheduler", "rng"} & set(payload)
    assert payload["data_manifest_hash"] == trainer.train_data.manifest["hash"]
    assert released.stat().st_size < (tmp_path / "run" / "last.pt").stat().st_size
    dataset = PreparedDataset(config.data, "train", config.model.window)
    name = dataset.sequence_names[0]
    batch = dataset.batch([(name, [0, 1])])
    with torch.no_grad():
        a = TrainingStep(load_model(tmp_path / "run" / "last.pt"))(batch).posed
        b = TrainingStep(load_model(released))(batch).posed
    assert torch.equal(a, b)


@pytest.mark.parametrize("setting,value,message", [
    ("landmarks", 32, r"descriptor has shape .* \(the model's landmarks is 32\)"),
    ("body_vertices", 64, r"body_distances has shape .* \(the model's body_vertices is 64\)"),
    ("levels", 3, r"its pooling hierarchy has 2 levels, the model pools 3 \(levels\)"),
])
def test_a_cache_prepared_for_another_model_is_refused_before_training(
        cache: Path, tmp_path: Path, setting: str, value: int, message: str) -> None:
    from dataclasses import replace

    config = config_for(cache, tmp_path / "run")
    config = replace(config, model=replace(config.model, **{setting: value}))
    with pytest.raises(ValueError, match=f"{cache}: .*: {message}: the cache was prepared"):
        make_trainer(config)
    assert not (tmp_path / "run").exists()
