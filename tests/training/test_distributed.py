"""Data-parallel training with torchrun (2 processes, gloo on CPU)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import torch

from gnngarment.model.checkpoint import load_checkpoint
from tests.synthetic_cache import build_synthetic_cache


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_torchrun_with_two_processes_trains_and_checkpoints(tmp_path: Path) -> None:
    cache = build_synthetic_cache(tmp_path / "cache", frames=4)
    config = tmp_path / "train.yaml"
    config.write_text(
        f"data: {cache}\noutput: {tmp_path / 'run'}\nmodel_config: configs/model/small.yaml\n"
        "model: {body_vertices: 32, landmarks: 16, levels: 2}\n"
        "epochs: 2\npairs_per_batch: 1\nframes_per_pair: 2\nthreads: 1\n"
        "stages: {max_epochs: [1, 1, 0]}\n")
    environment = {**os.environ, "OMP_NUM_THREADS": "1"}
    result = subprocess.run(
        [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node", "2",
         "-m", "gnngarment.cli", "train", "--config", str(config)],
        capture_output=True, text=True, env=environment, cwd=Path(__file__).parents[2],
        timeout=540)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    payload = load_checkpoint(tmp_path / "run" / "last.pt")
    assert payload["epoch"] == 2 and payload["schedule"]["stage"] == "physics_strain"
    # Stage 2 trained the physics submodule in both processes (weights left zero-init).
    assert torch.count_nonzero(payload["model_state"]["physics_processor.output.lin.weight"]) > 0
