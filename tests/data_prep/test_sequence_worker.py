"""The sequence worker computes on one thread, whatever the caller set: the cache's bits
must not depend on the machine's cores (the drape worker's test says why)."""

from __future__ import annotations

from pathlib import Path

from threadpoolctl import threadpool_info, threadpool_limits

from data_prep import sequence_worker
from data_prep.plan import plan_dataset
from tests.data_prep.test_build import tiny_config


def test_the_sequence_worker_runs_on_one_thread(monkeypatch, tmp_path: Path) -> None:
    import torch

    seen: list[set[int]] = []

    def record(*_: object) -> None:
        seen.append({pool["num_threads"] for pool in threadpool_info()}
                    | {torch.get_num_threads()})
        raise RuntimeError("stop here")

    monkeypatch.setattr(sequence_worker, "anny_body_model", record)
    config = tiny_config(tmp_path / "data")
    plan = plan_dataset(config)[0]
    before = torch.get_num_threads()
    with threadpool_limits(limits=2):
        torch.set_num_threads(2)
        try:
            status = sequence_worker.simulate_sequence(
                (str(tmp_path / "data"), plan, config, "hash"))
        finally:
            torch.set_num_threads(before)
    assert seen == [{1}]
    assert "stop here" in str(status)  # reported as crashed, not raised
