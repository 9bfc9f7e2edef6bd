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
