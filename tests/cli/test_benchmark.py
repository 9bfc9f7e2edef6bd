from __future__ import annotations

from pathlib import Path

import pytest

from gnngarment.cli.benchmark import run_benchmark
from gnngarment.training.config import StageConfig, TrainingConfig
from tests.model.pairs import tiny_config
from tests.synthetic_cache import build_synthetic_cache


@pytest.mark.slow
def test_benchmark_trains_variants_and_writes_the_table(tmp_path: Path) -> None:
    cache = build_synthetic_cache(tmp_path / "cache", frames=4)
    config = TrainingConfig(data=str(cache), output=str(tmp_path / "runs"), model=tiny_config(),
                            epochs=2, pairs_per_batch=2, frames_per_pair=2, threads=1,
                            stages=StageConfig(max_epochs=[1, 1, 0]))
    result = run_benchmark(config, tmp_path / "results.md",
                           ["ours (2 levels)", "single level"], command="test")
    assert set(result["rows"]) == {"body skinning (draped template)", "ours (2 levels), supervised",
                                   "ours (2 levels), + physics", "single level, supervised",
                                   "single level, + physics"}
    table = (tmp_path / "results.md").read_text()
    assert "| single level, + physics |" in table and "Command: `test`" in table
