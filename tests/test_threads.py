"""The thread count a run picks: the cores idle now (a second thread on a core another
process keeps busy makes every parallel operator wait for it)."""

from __future__ import annotations

import os

import pytest

from gnngarment import threads


def test_idle_cores_is_a_share_of_the_machine() -> None:
    idle = threads.idle_cores(0.05)
    assert idle is None or 0.0 <= idle <= (os.cpu_count() or 1)


@pytest.mark.parametrize(("idle", "cores", "expected"), [
    (1.97, 2, 2),   # a quiet 2-core machine: both
    (0.97, 2, 1),   # another process busy on one core: one thread, not two
    (0.05, 2, 1),   # everything busy: still one
    (7.6, 4, 4),    # never more than this process may use
    (None, 3, 3),   # unknown (no /proc/stat): every usable core
])
def test_threads_follow_the_idle_cores(monkeypatch, idle, cores, expected) -> None:
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    monkeypatch.setattr(threads, "idle_cores", lambda sample_seconds: idle)
    monkeypatch.setattr(threads, "usable_cores", lambda: cores)
    assert threads.choose_threads() == expected


def test_omp_num_threads_wins(monkeypatch) -> None:
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    monkeypatch.setattr(threads, "idle_cores", lambda sample_seconds: 0.1)
    assert threads.choose_threads() == 3


def test_one_thread_limits_torch_and_blas_and_restores() -> None:
    """Inside the block every BLAS/OpenMP library and torch run one thread (so a build's
    LAPACK results do not depend on the machine's cores); after it, what was set before."""
    import numpy  # noqa: F401  (loads OpenBLAS, so that there is a BLAS to limit)
    import torch
    from threadpoolctl import threadpool_info, threadpool_limits

    torch_before = torch.get_num_threads()
    with threadpool_limits(limits=2):
        torch.set_num_threads(2)
        try:
            with threads.one_thread():
                assert torch.get_num_threads() == 1
                assert {pool["num_threads"] for pool in threadpool_info()} == {1}
            assert torch.get_num_threads() == 2
            assert {pool["num_threads"] for pool in threadpool_info()} == {2}
        finally:
            torch.set_num_threads(torch_before)
