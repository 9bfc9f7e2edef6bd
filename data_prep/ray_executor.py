"""Run a build's worker tasks as Ray tasks (``prepare --executor ray``).

One Ray task per call (one per sequence, one per (design, body) drape). Ray reuses its
worker processes across tasks, so what a worker process keeps (the Anny body model of
:mod:`data_prep.bodies`, Warp's loaded kernels) is built once per worker process, not per task.
A worker process that dies mid-task (SIGKILL, OOM killer, a lost node) is retried by Ray
(``max_retries``); the worker functions write every file to a temporary name and rename
it, so a killed attempt leaves no half-written file, only a hidden temporary that the
build removes before it writes the manifest.

Ray is an optional dependency (``pip install -e .[ray]``), imported only when a
:class:`RayExecutor` is made.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

from data_prep.executor import ClosedOnExit

#: Ray's task retries after a worker process died (Ray's own default is 3).
MAX_RETRIES = 3


class RayMissingError(ImportError):
    """``--executor ray`` without Ray installed (the message says how to install it)."""


def import_ray() -> Any:
    """The ``ray`` module.

    Raises:
        RayMissingError: Ray is not installed.
    """
    try:
        import ray
    except ImportError as error:
        raise RayMissingError(
            f"--executor ray needs Ray ({error}): pip install -e '.[ray]' (or pip install "
            "'ray==2.60.0')") from None
    return ray


class RayExecutor(ClosedOnExit):
    """Maps worker functions over a Ray cluster.

    Args:
        address: the cluster to join (``"auto"``, ``"HOST:6379"``, ``"ray://HOST:10001"``);
            ``""``: the Ray this process already initialised, else the one the
            ``RAY_ADDRESS`` environment variable names, else one started with ``ray
            start`` on this machine, else a new one here (stopped on :meth:`close`).
        max_in_flight: the most tasks submitted at once (``None``: all; the cluster's CPUs
            then decide how many run).
        max_retries: Ray's retries of a task whose worker process died.

    Raises:
        RayMissingError: Ray is not installed.
        ConnectionError: ``address`` names no reachable cluster (Ray's error).
    """

    def __init__(self, address: str = "", max_in_flight: int | None = None,
                 max_retries: int = MAX_RETRIES) -> None:
        if max_in_flight is not None and max_in_flight < 1:
            raise ValueError(f"max_in_flight must be >= 1 or None, got {max_in_flight}")
        self._ray = import_ray()
        self.max_in_flight = max_in_flight
        self.max_retries = max_retries
        # Shut down only a Ray this executor started or joined, never the caller's.
        self._owned = not self._ray.is_initialized()
        if self._owned:
            self._ray.init(address=address or None, include_dashboard=False,
                           log_to_driver=True)

    def cluster_cpus(self) -> int:
        """The CPUs of the cluster (all nodes) Ray schedules on."""
        return int(self._ray.cluster_resources().get("CPU", 1))

    def imap_unordered(self, function: Callable[[Any], Any], tasks: list[Any],
                       lost: Callable[[Any, Exception], Any] | None = None) -> Iterator[Any]:
        """``function(task)`` for every task as a Ray task (1 CPU each), yielded as each
        finishes; a task whose worker died ``max_retries + 1`` times yields
        ``lost(task, error)`` (or raises Ray's error if ``lost`` is ``None``)."""
        ray = self._ray
        remote = ray.remote(function).options(num_cpus=1, max_retries=self.max_retries)
        limit = self.max_in_flight or len(tasks)
        waiting = iter(tasks)
        pending: dict[Any, Any] = {}  # object ref -> its task

        def submit() -> None:
            for task in waiting:
                pending[remote.remote(task)] = task
                if len(pending) >= limit:
                    return

        submit()
        try:
            while pending:
                (ref,), _ = ray.wait(list(pending), num_returns=1)
                task = pending.pop(ref)
                submit()
                try:
                    yield ray.get(ref)
                except ray.exceptions.RayError as error:
                    if lost is None:
                        raise
                    yield lost(task, error)
        finally:
            for ref in pending:  # a build stopped early (an error, Ctrl-C)
                ray.cancel(ref, force=True)

    def parallelism(self, tasks: int) -> int:
        return min(self.max_in_flight or self.cluster_cpus(), max(tasks, 1))

    def describe(self) -> str:
        nodes = sum(1 for node in self._ray.nodes() if node.get("Alive"))
        return f"Ray: {nodes} node(s), {self.cluster_cpus()} CPU(s)"

    def close(self) -> None:
        if self._owned and self._ray.is_initialized():
            self._ray.shutdown()
