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
        # 3 batches per epoch on 2 ranks: without padding one rank takes a step the
        # other does not, and DDP waits for it forever (it did before rank_share).
        "epochs: 2\npairs_per_batch: 2\nframes_per_pair: 3\nthreads: 1\n"
        "stages: {max_epochs: [1, 1, 0]}\n")
    environment = {**os.environ, "OMP_NUM_THREADS": "1"}
    result = subprocess.run(
        [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node", "2",
         "-m", "gnngarment.cli", "train", "--config", str(config)],
        capture_output=True, text=True, env=environment, cwd=Path(__file__).parents[2],
        timeout=240)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    payload = load_checkpoint(tmp_path / "run" / "last.pt")
    assert payload["epoch"] == 2 and payload["schedule"]["stage"] == "physics_strain"
    # Stage 2 trained the physics submodule in both processes (weights left zero-init).
    assert torch.count_nonzero(payload["model_state"]["physics_processor.output.lin.weight"]) > 0


def _mean_in_rank(rank: int, init_file: str, results: str) -> None:
    import json

    from gnngarment.training.trainer import mean_over_ranks

    torch.distributed.init_process_group("gloo", init_method=f"file://{init_file}",
                                         rank=rank, world_size=2)
    try:
        # Rank 0 saw 3 batches of loss 1, rank 1 one batch of loss 5: the epoch's mean
        # is 2 on both ranks (each rank's own mean, 1 and 5, would switch stages apart).
        sums, count = ({"loss": 3.0, "vertex": 0.3}, 3) if rank == 0 else \
            ({"vertex": 0.5, "loss": 5.0}, 1)
        Path(results, f"{rank}.json").write_text(json.dumps(mean_over_ranks(sums, count)))
    finally:
        torch.distributed.destroy_process_group()


@pytest.mark.timeout(120)
def test_every_rank_gets_the_mean_over_all_ranks(tmp_path: Path) -> None:
    import json

    torch.multiprocessing.spawn(_mean_in_rank, args=(str(tmp_path / "init"), str(tmp_path)),
                                nprocs=2)
    means = [json.loads((tmp_path / f"{rank}.json").read_text()) for rank in (0, 1)]
    assert means[0] == means[1]
    assert means[0]["loss"] == pytest.approx(2.0)
    assert means[0]["vertex"] == pytest.approx(0.2)


def test_every_rank_takes_as_many_steps_and_all_batches_are_seen() -> None:
    from gnngarment.training.trainer import rank_share

    batches = list(range(5))
    shares = [rank_share(batches, rank, 2) for rank in (0, 1)]
    assert [len(share) for share in shares] == [3, 3]
    assert set(shares[0]) | set(shares[1]) == set(batches)
    assert rank_share(batches, 0, 1) == batches
    assert [len(rank_share(batches[:1], rank, 3)) for rank in range(3)] == [1, 1, 1]
