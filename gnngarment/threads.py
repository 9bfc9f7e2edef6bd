"""How many torch threads a run should use: the cores that are idle now, not the cores
the machine has.

Intra-op parallel operators wait for their slowest thread. With another process busy
on one of two cores, a second thread is descheduled most of the time and every
operator waits for it: measured 10-40x slower than one thread at batch 1
(docs/experiments/2026-12-02-speed-threads-skinning-size.md). So a run counts the cores
other processes leave idle (a short sample of ``/proc/stat``) and uses that many, at least one.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

#: How long the idle cores are sampled (s).
SAMPLE_SECONDS = 0.2


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def _cpu_times() -> tuple[int, int] | None:
    """(busy, total) jiffies of the whole machine, from ``/proc/stat``; ``None`` when it
    cannot be read (not Linux)."""
    try:
        fields = Path("/proc/stat").read_text().splitlines()[0].split()
    except OSError:
        return None
    values = [int(value) for value in fields[1:9]]
    idle = values[3] + values[4]  # idle + iowait
    return sum(values) - idle, sum(values)


def idle_cores(sample_seconds: float = SAMPLE_SECONDS) -> float | None:
    """Cores left idle by every process on the machine over a short sample (this
    process sleeps through it, so it does not count itself); ``None`` when unknown."""
    before = _cpu_times()
    if before is None:
        return None
    time.sleep(sample_seconds)
    after = _cpu_times()
    busy, total = after[0] - before[0], after[1] - before[1]
    if total <= 0:
        return None
    machine = os.cpu_count() or 1
    return machine * (1.0 - busy / total)


def choose_threads(sample_seconds: float = SAMPLE_SECONDS) -> int:
    """The intra-op thread count for this run: the idle cores (rounded to the nearest,
    at least 1, at most :func:`usable_cores`). ``OMP_NUM_THREADS``, when set, wins."""
    given = os.environ.get("OMP_NUM_THREADS", "")
    if given.isdigit() and int(given) > 0:
        return int(given)
    cores = usable_cores()
    idle = idle_cores(sample_seconds)
    if idle is None:
        return cores
    return max(1, min(cores, int(idle + 0.5)))


def use_idle_cores() -> int:
    """Set torch's intra-op threads to :func:`choose_threads` and return the count."""
    import torch

    threads = choose_threads()
    torch.set_num_threads(threads)
    return threads


@contextmanager
def one_thread() -> Iterator[None]:
    """Torch and the BLAS/OpenMP libraries (numpy's, scipy's, torch's) on one thread
    inside the block, each restored after; also a decorator.

    For work whose results must not depend on the machine's cores: LAPACK's eigenvalues
    of the same matrix differ in the last bits between one and two threads (the Nyström
    descriptors of a dataset build, ≤ 1.7e-15), which changed a cache's manifest hash
    from one machine to another; and for workers that already run one per core.
    """
    import torch
    from threadpoolctl import threadpool_limits

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        with threadpool_limits(limits=1):
            yield
    finally:
        torch.set_num_threads(threads)
