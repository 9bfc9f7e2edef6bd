"""Simulation throughput of `gnngarment prepare`: the local process pool vs Ray tasks.

The garments of the config are draped once; then, for each executor and worker count,
every sequence is simulated again from those drapes (a copy of the cache without
``sequences/`` and ``raw/``) and the simulated frames per second of wall-clock time are
printed, the start of the executor's workers included (a fresh pool or a fresh Ray
instance per run; starting Ray itself is shown apart). Also measures Ray's overhead per
task on a no-op task, against the process pool's.

    .venv/bin/python benchmarks/ray_throughput.py [--config configs/data/tiny.yaml]
        [--motion-seconds 2.0] [--workers 1 2] [--tasks 500]

Needs Ray (``pip install -e .[ray]``). Ray runs on this machine only.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import shutil
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from data_prep.build import build_dataset
from data_prep.config import DataConfig
from gnngarment.config import load_config
from gnngarment.paths import REPOSITORY_ROOT


def noop(task: int) -> int:
    """The task whose cost is pure executor overhead."""
    return task


def start_ray(cpus: int):
    """A fresh local Ray instance of ``cpus`` CPUs; returns (ray, seconds to start it)."""
    import ray

    started = time.perf_counter()
    ray.init(address="local", num_cpus=cpus, include_dashboard=False,
             log_to_driver=False)
    return ray, time.perf_counter() - started


def simulate_all(base: Path, config: DataConfig, executor: str, workers: int
                 ) -> dict[str, float]:
    """Simulate every sequence of ``config`` from the drapes in ``base``.

    Returns:
        ``frames`` (of the sequences kept: one that fails the quality gates is simulated
        but not counted), ``seconds`` (wall clock of the build) and ``frames_per_s``,
        ``sequences`` (simulated) and ``kept``, plus
        ``ray_start_s`` (starting Ray, not in ``seconds``) for the Ray executor.
    """
    root = Path(tempfile.mkdtemp(prefix=f"{executor}{workers}_", dir=base.parent))
    shutil.copytree(base, root, dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns("sequences", "raw", "manifest.json",
                                                  "build_report.json", ".lock"))
    run = replace(config, output=str(root), executor=executor, workers=workers)
    extra = {}
    if executor == "ray":
        ray, extra["ray_start_s"] = start_ray(cpus=2)
    try:
        started = time.perf_counter()
        report = build_dataset(run, log=lambda _: None)
        seconds = time.perf_counter() - started
    finally:
        if executor == "ray":
            ray.shutdown()
    if report["simulated"] == 0:
        raise RuntimeError(f"{root}: nothing simulated ({report})")
    manifest = json.loads((root / "manifest.json").read_text())
    frames = sum(info["frames"] for info in manifest["sequences"].values())
    shutil.rmtree(root)
    return {"frames": frames, "seconds": seconds, "frames_per_s": frames / seconds,
            "sequences": report["simulated"], "kept": len(manifest["sequences"]), **extra}


def ray_overhead(tasks: int) -> dict[str, float]:
    """Per-task overhead [ms] of Ray and of a spawn process pool on a no-op task: one
    task at a time (submit, wait, get) and ``tasks`` tasks in flight over 2 workers."""
    from data_prep.ray_executor import RayExecutor

    ray, _ = start_ray(cpus=2)
    try:
        with RayExecutor(max_in_flight=1) as one:
            list(one.imap_unordered(noop, list(range(20))))  # start the workers
            started = time.perf_counter()
            list(one.imap_unordered(noop, list(range(tasks))))
            ray_serial = (time.perf_counter() - started) / tasks
        with RayExecutor() as many:
            started = time.perf_counter()
            list(many.imap_unordered(noop, list(range(tasks))))
            ray_parallel = (time.perf_counter() - started) / tasks
    finally:
        ray.shutdown()
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        list(pool.imap_unordered(noop, range(20)))
        started = time.perf_counter()
        for task in range(tasks):
            pool.apply(noop, (task,))
        pool_serial = (time.perf_counter() - started) / tasks
        started = time.perf_counter()
        list(pool.imap_unordered(noop, range(tasks)))
        pool_parallel = (time.perf_counter() - started) / tasks
    return {"ray_serial_ms": 1000 * ray_serial, "ray_parallel_ms": 1000 * ray_parallel,
            "pool_serial_ms": 1000 * pool_serial, "pool_parallel_ms": 1000 * pool_parallel}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--config", type=Path,
                        default=REPOSITORY_ROOT / "configs" / "data" / "tiny.yaml")
    parser.add_argument("--motion-seconds", type=float, default=2.0,
                        help="length of every motion [s] (tiny's 0.2 s is all start-up)")
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--tasks", type=int, default=500, help="no-op tasks for the overhead")
    args = parser.parse_args()

    config = load_config(args.config, DataConfig)
    config = replace(config, motion_seconds=args.motion_seconds,
                     simulation=str(REPOSITORY_ROOT / config.simulation))
    with tempfile.TemporaryDirectory(prefix="ray_throughput_") as folder:
        base = Path(folder) / "base"
        started = time.perf_counter()
        build_dataset(replace(config, output=str(base)), log=lambda _: None)
        print(f"drapes and a first build: {time.perf_counter() - started:.0f} s")
        rows = []
        for workers in args.workers:
            for executor in ("local", "ray"):
                result = simulate_all(base, config, executor, workers)
                rows.append((executor, workers, result))
    overhead = ray_overhead(args.tasks)

    print(f"\n{args.config.name}, motion_seconds {args.motion_seconds}: "
          f"{rows[0][2]['sequences']} sequences simulated per build, {rows[0][2]['kept']} "
          f"kept ({rows[0][2]['frames']} frames)\n")
    print("| executor | workers | build [s] | frames/s | Ray start [s] |")
    print("|---|---|---|---|---|")
    for executor, workers, result in rows:
        start = f"{result['ray_start_s']:.1f}" if "ray_start_s" in result else "-"
        print(f"| {executor} | {workers} | {result['seconds']:.1f} | "
              f"{result['frames_per_s']:.1f} | {start} |")
    print(f"\nper no-op task [ms], {args.tasks} tasks: Ray {overhead['ray_serial_ms']:.2f} "
          f"one at a time, {overhead['ray_parallel_ms']:.2f} all in flight (2 CPUs); "
          f"process pool {overhead['pool_serial_ms']:.2f} one at a time, "
          f"{overhead['pool_parallel_ms']:.2f} all in flight (2 processes)")


if __name__ == "__main__":
    main()
