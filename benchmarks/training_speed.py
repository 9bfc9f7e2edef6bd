"""Training throughput: optimiser steps/s and frames/s of each training stage.

Runs the trainer's own step (:meth:`~gnngarment.training.trainer.Trainer.step`: forward,
the stage's loss, Adamax) on a prepared cache for a
fixed number of batches per stage — supervised (all parameters, vertex + edge + normal
losses), physics (second M^mp only; collision + gravity) and physics with strain
(+ stretch + shear) — and prints seconds per step, frames/s and vertices/s. Batches are
the trainer's (``pairs_per_batch`` garment–body pairs × ``frames_per_pair`` frames,
mixed garments).

    .venv/bin/python benchmarks/training_speed.py [--config configs/train/demo.yaml]
        [--data data/demo] [--steps 10] [--threads 1] [--deterministic on|off|both]
        [--processes 1] [--set pairs_per_batch=1 ...] [--attention-path fused pytorch]
        [--profile ROWS]

``--attention-path fused pytorch`` measures the same run with the GAT layers on the fused
C++ operator (:mod:`gnngarment.model.fused_attention`) and on its PyTorch fallback, one
after the other in this process, and prints the ratio per stage (``auto``, the default:
whatever the library chooses, one run).

``--processes P`` measures data-parallel training as ``torchrun --nproc_per_node P``
runs it: P processes (gloo, ``--threads`` threads each), each stepping on its own batch
with gradients averaged by DDP (:meth:`Trainer.wrap_for_stage`); frames/s counts every
rank's frames over the slowest rank's time. With P processes one step trains on P
batches; ``--set pairs_per_batch=...`` keeps the global batch of a one-process run.

Freed memory is kept for reuse as every ``gnngarment`` command keeps it
(:func:`gnngarment.allocator.keep_freed_memory`); ``GNNGARMENT_KEEP_FREED_MEMORY=0``
measures with glibc's defaults.

``--deterministic both`` measures the run with torch's deterministic algorithms off and
on (the training default), in that order in one process, and prints the ratio.

Without a prepared cache at ``--data`` it prints how to build one and exits 2.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from gnngarment.allocator import keep_freed_memory  # noqa: E402
from gnngarment.data import PreparedDataset  # noqa: E402
from gnngarment.model.fused_attention import (  # noqa: E402
    attention_path,
    fallback_reason,
    use_attention_path,
)
from gnngarment.training.loading import load_training_config  # noqa: E402
from gnngarment.training.trainer import Trainer, set_stage  # noqa: E402

STAGES = ("supervised", "physics", "physics_strain")


def measure(config_path: Path, data: Path, steps: int, threads: int,
            deterministic: bool = True, overrides: list[str] | None = None,
            profile_rows: int = 0) -> dict:
    """Seconds per optimiser step (:meth:`Trainer.step`) for each stage, the first step of
    each stage discarded as a warm-up. With ``profile_rows``, each stage's steps after
    the warm-up also run once more under torch's profiler and its table of that many
    operators (by self time) is kept under ``"profile"``. Returns a JSON-able dict.
    Inside a process group (``--processes``) every rank steps on its own batches and the
    figures are the group's: frames of all ranks, the slowest rank's seconds."""
    config = load_training_config(config_path, [f"data={data}", f"threads={threads}",
                                                f"deterministic={deterministic}",
                                                *(overrides or [])])
    dataset = PreparedDataset(config.data, "train", config.model.window)
    trainer = Trainer(config, dataset, None, progress=False)
    rank, world = trainer.rank, trainer.world
    rng = np.random.default_rng(config.seed)
    groups = list(dataset.batches(config.pairs_per_batch, config.frames_per_pair, rng))
    results = {"config": str(config_path), "data": str(data), "threads": threads,
               "processes": world, "deterministic": deterministic,
               "pairs_per_batch": config.pairs_per_batch,
               "frames_per_pair": config.frames_per_pair, "stages": {}}
    for stage in STAGES:
        trainer.stages.stage = stage
        set_stage(trainer.model, stage)
        trainer.wrap_for_stage()
        trainer.step_module.train()
        times, frames, vertices = [], 0, 0
        for index in range(steps + 1):
            items = groups[(index * world + rank) % len(groups)]
            tic = time.perf_counter()
            trainer.step(items)
            elapsed = time.perf_counter() - tic
            if index == 0:
                continue  # warm-up: cached graph structures, allocator
            times.append(elapsed)
            for name, chunk in items:
                frames += len(chunk)
                vertices += len(chunk) * len(dataset.garment_of(name).pair.rest_pos)
        seconds = float(np.sum(times))
        median = float(np.median(times))
        if world > 1:
            totals = torch.tensor([frames, vertices], dtype=torch.float64)
            slowest = torch.tensor([seconds, median], dtype=torch.float64)
            torch.distributed.all_reduce(totals)
            torch.distributed.all_reduce(slowest, op=torch.distributed.ReduceOp.MAX)
            (frames, vertices), (seconds, median) = totals.tolist(), slowest.tolist()
        results["stages"][stage] = {
            "seconds_per_step": seconds / steps, "median_seconds_per_step": median,
            "frames_per_second": frames / seconds, "vertices_per_second": vertices / seconds}
        if profile_rows:
            from torch.profiler import ProfilerActivity, profile

            with profile(activities=[ProfilerActivity.CPU]) as profiled:
                for index in range(1, steps + 1):
                    trainer.step(groups[(index * world + rank) % len(groups)])
            results["stages"][stage]["profile"] = profiled.key_averages().table(
                sort_by="self_cpu_time_total", row_limit=profile_rows)
    return results


def _rank(rank: int, world: int, init_file: str, args: argparse.Namespace,
          deterministic: bool, output: str) -> None:
    """One process of ``--processes``: join the gloo group, measure, rank 0 writes."""
    torch.distributed.init_process_group("gloo", init_method=f"file://{init_file}",
                                         rank=rank, world_size=world)
    try:
        keep_freed_memory()
        results = measure(args.config, args.data, args.steps, args.threads, deterministic,
                          args.set)
        if rank == 0:
            Path(output).write_text(json.dumps(results))
    finally:
        torch.distributed.destroy_process_group()


def measure_in_processes(args: argparse.Namespace, deterministic: bool) -> dict:
    """:func:`measure` in ``args.processes`` processes (one gloo group, as torchrun)."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        output = Path(folder) / "results.json"
        torch.multiprocessing.spawn(
            _rank, args=(args.processes, str(Path(folder) / "init"), args, deterministic,
                         str(output)), nprocs=args.processes)
        return json.loads(output.read_text())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--config", type=Path, default=ROOT / "configs/train/demo.yaml")
    parser.add_argument("--data", type=Path, default=ROOT / "data/demo")
    parser.add_argument("--steps", type=int, default=10)
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--deterministic", choices=("on", "off", "both"), default="on")
    parser.add_argument("--processes", type=int, default=1,
                        help="data-parallel processes (gloo + DDP, as torchrun runs them)")
    parser.add_argument("--set", action="append", default=[],
                        help="override a training setting, e.g. --set pairs_per_batch=1")
    parser.add_argument("--attention-path", nargs="+", choices=("auto", "fused", "pytorch"),
                        default=["auto"],
                        help="GAT path(s) to measure, each a run of its own (auto: the "
                             "library's choice)")
    parser.add_argument("--profile", type=int, default=0, metavar="ROWS",
                        help="also profile each stage's steps once more and print its "
                             "ROWS operators of most self time")
    parser.add_argument("--json", type=Path, help="also write the results here")
    args = parser.parse_args()
    if args.processes < 1:
        print(f"--processes must be >= 1, got {args.processes}", file=sys.stderr)
        raise SystemExit(2)
    if not (args.data / "manifest.json").is_file():
        print(f"{args.data}: no prepared cache (build it with `gnngarment prepare --config "
              "configs/data/demo.yaml`, or `make demo`)", file=sys.stderr)
        raise SystemExit(2)
    # As `gnngarment train` does (GNNGARMENT_KEEP_FREED_MEMORY=0: glibc's defaults).
    kept = keep_freed_memory()
    print(f"torch {torch.__version__}, {args.processes} process(es) × {args.threads} "
          f"thread(s), load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, freed memory "
          f"{'kept for reuse' if kept else 'unmapped (glibc default)'}")
    modes = {"on": [True], "off": [False], "both": [False, True]}[args.deterministic]
    runs = []
    for path in dict.fromkeys(args.attention_path):
        with use_attention_path(None if path == "auto" else path):
            training_path = attention_path(grad=True)
            reason = fallback_reason(grad=True)
            for mode in modes:
                results = (measure(args.config, args.data, args.steps, args.threads, mode,
                                   args.set, args.profile)
                           if args.processes == 1 else measure_in_processes(args, mode))
                results["attention_path"] = path
                results["path"] = training_path + (f" ({reason})" if reason else "")
                runs.append(results)
    for results in runs:
        print(f"{results['pairs_per_batch']} pairs × {results['frames_per_pair']} frames per "
              f"batch and process, {results['processes']} process(es), {args.steps} steps "
              f"per stage after one warm-up step, {args.data}, "
              f"deterministic {'on' if results['deterministic'] else 'off'}, GAT path "
              f"{results['attention_path']} = {results['path']}")
        print("| stage | s/step (mean) | s/step (median) | frames/s | vertices/s |")
        print("|---|---|---|---|---|")
        for stage, row in results["stages"].items():
            print(f"| {stage} | {row['seconds_per_step']:.3f} | "
                  f"{row['median_seconds_per_step']:.3f} | {row['frames_per_second']:.1f} | "
                  f"{row['vertices_per_second']:.0f} |")
        for stage, row in results["stages"].items():
            if "profile" in row:
                print(f"profile of {args.steps} {stage} steps:\n{row['profile']}")
    median = "median_seconds_per_step"
    if len(modes) == 2:
        for before, after in zip(runs[::2], runs[1::2], strict=True):
            ratios = ", ".join(f"{stage} {after['stages'][stage][median] / row[median]:.2f}x"
                               for stage, row in before["stages"].items())
            print(f"deterministic on / off, median s/step ({before['attention_path']}): "
                  f"{ratios}")
    by_path = {(r["attention_path"], r["deterministic"]): r for r in runs}
    for mode in modes:
        fused, fallback = by_path.get(("fused", mode)), by_path.get(("pytorch", mode))
        if fused and fallback:
            ratios = ", ".join(
                f"{stage} {fallback['stages'][stage][median] / row[median]:.2f}x"
                for stage, row in fused["stages"].items())
            print(f"fused ÷ pytorch steps/s (median s/step ratio), deterministic "
                  f"{'on' if mode else 'off'}: {ratios}")
    if args.json:
        args.json.write_text(json.dumps(runs if len(runs) > 1 else runs[0], indent=2))


if __name__ == "__main__":
    main()
