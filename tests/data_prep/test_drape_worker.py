"""The drape worker computes on one thread, whatever the caller set: the cache's bits
must not depend on the machine's cores (LAPACK's eigenvalues of the Nyström descriptor
differ in the last bits between one and two threads)."""

from __future__ import annotations

from pathlib import Path

from threadpoolctl import threadpool_info, threadpool_limits

from data_prep import drape_worker
from data_prep.plan import plan_dataset
from tests.data_prep.test_build import tiny_config


def test_the_drape_worker_runs_on_one_thread(monkeypatch, tmp_path: Path) -> None:
    import torch

    seen: list[set[int]] = []

    def record(*_: object) -> None:
        seen.append({pool["num_threads"] for pool in threadpool_info()}
                    | {torch.get_num_threads()})
        raise RuntimeError("stop here")

    monkeypatch.setattr(drape_worker, "anny_body_model", record)
    config = tiny_config(tmp_path / "data")
    plan = plan_dataset(config)[0]
    before = torch.get_num_threads()
    with threadpool_limits(limits=2):
        torch.set_num_threads(2)
        try:
            status = drape_worker.drape_and_prepare_garment(
                (str(tmp_path / "data"), plan.design, plan.body, config, "hash"))
        finally:
            torch.set_num_threads(before)
    assert seen == [{1}]
    assert "stop here" in str(status)  # reported as crashed, not raised
