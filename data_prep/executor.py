"""Where a build's worker tasks run: a local process pool (the default) or a Ray cluster.

An executor maps a module-level worker function over picklable task arguments and
yields the results as they finish (in any order). The build (:mod:`data_prep.build`)
knows nothing else about it: the same plan, the same worker functions and the same
files, whether on 2 cores or 200.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
from collections.abc import Callable, Iterator
from typing import Any, Protocol, Self

#: The executors ``DataConfig.executor`` and ``prepare --executor`` accept.
EXECUTORS = ("local", "ray")


class Executor(Protocol):
    """Runs worker tasks; use as a context manager (closing stops its workers)."""

    def imap_unordered(self, function: Callable[[Any], Any], tasks: list[Any],
                       lost: Callable[[Any, Exception], Any] | None = None) -> Iterator[Any]:
        """``function(task)`` for every task, yielded as each finishes.

        Args:
            function: a module-level function (workers import it by name).
            tasks: its arguments, one per call.
            lost: the result to yield for a task whose worker died more times than the
                executor retries (``lost(task, error)``); ``None``: raise instead. A
                local pool never calls it.
        """
        ...

    def parallelism(self, tasks: int) -> int:
        """How many of ``tasks`` tasks run at once."""
        ...

    def describe(self) -> str:
        """Where the tasks run, for the build log ("" for the local pool)."""
        ...

    def close(self) -> None:
        """Stop the workers (tasks still running are abandoned)."""
        ...

    def __enter__(self) -> Executor: ...

    def __exit__(self, *exc_info: object) -> None: ...


def stop_with_parent(parent: int) -> None:
    """Pool-worker initializer: end this worker when the build that started it dies.

    A build killed with SIGKILL cannot terminate its pool, and a worker would go on
    simulating (and writing into the cache) for the rest of its task. On Linux the
    kernel sends the worker SIGKILL when its parent dies (``PR_SET_PDEATHSIG``); if the
    parent is already gone by the time this runs, the worker exits at once. Elsewhere
    the worker finishes its task alone (the next build's lock and temp-file cleanup
    still hold).
    """
    if sys.platform.startswith("linux"):
        import ctypes
        import signal

        set_parent_death_signal = 1  # PR_SET_PDEATHSIG, <linux/prctl.h>
        ctypes.CDLL(None, use_errno=True).prctl(set_parent_death_signal, signal.SIGKILL)
    if os.getppid() != parent:
        os._exit(1)


class ClosedOnExit:
    """``with executor:`` closes it on the way out — the one context-manager part the
    local pool and the Ray executor share."""

    def close(self) -> None:
        raise NotImplementedError

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


class LocalExecutor(ClosedOnExit):
    """A ``spawn`` process pool on this machine, made at the first non-empty map with
    ``min(workers, len(tasks))`` processes and reused by the later maps (so each worker
    process keeps its body model and compiled kernels across tasks)."""

    def __init__(self, workers: int) -> None:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        self.workers = workers
        self._pool: Any = None

    def imap_unordered(self, function: Callable[[Any], Any], tasks: list[Any],
                       lost: Callable[[Any, Exception], Any] | None = None) -> Iterator[Any]:
        if not tasks:
            return iter(())
        if self._pool is None:
            self._pool = multiprocessing.get_context("spawn").Pool(
                self.parallelism(len(tasks)), initializer=stop_with_parent,
                initargs=(os.getpid(),))
        return self._pool.imap_unordered(function, tasks)

    def parallelism(self, tasks: int) -> int:
        return min(self.workers, max(tasks, 1))

    def describe(self) -> str:
        return ""

    def close(self) -> None:
        if self._pool is not None:
            self._pool.terminate()
            self._pool.join()
            self._pool = None


def make_executor(kind: str, workers: int | None, address: str = "") -> Executor:
    """The executor ``kind`` names.

    Args:
        kind: ``"local"`` or ``"ray"``.
        workers: local: processes (``None``: one per core); Ray: the most tasks in
            flight at once (``None``: as many as the cluster has CPUs).
        address: Ray only: the cluster to join (``"auto"``, ``"HOST:6379"``,
            ``"ray://HOST:10001"``); ``""`` joins the Ray this process already runs, else
            the one ``RAY_ADDRESS`` names, else one ``ray start`` started on this
            machine, else starts one here.

    Raises:
        ValueError: unknown ``kind``.
        RayMissingError: ``kind="ray"`` and Ray is not installed (an ``ImportError``).
    """
    if kind == "local":
        return LocalExecutor(workers or os.cpu_count() or 1)
    if kind == "ray":
        from data_prep.ray_executor import RayExecutor

        return RayExecutor(address=address, max_in_flight=workers)
    raise ValueError(f"unknown executor '{kind}'; known: {', '.join(EXECUTORS)}")

