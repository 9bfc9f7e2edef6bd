"""Does a garment's response to motion transfer to a new motion once it has been seen in
*many* motions? The learning curve of per-garment bounds over the number of motions.

``dynamics_bounds.py`` found that nothing fitted to a pair's two other motions transfers
(fixed weights 1.02× body skinning, a linear response worse). The benchmark gives a
model only 3 motions per (design, body) pair, so that result cannot tell "the response
is not a function of the motion a model can learn" from "two motions are too few to
identify it". This script measures the curve: one test design per garment type on the
first test body of ``--config`` (default ``configs/data/benchmark_cmu.yaml``; the drapes
``simulation_spread.py`` made in ``--work`` are reused, else made), simulated by the
builder's path on ``--train-windows`` CMU windows of the *training* subjects and
``--test-windows`` windows of the *test* subjects. For ``k`` training windows (random
draws, ``--draws`` each), per-garment models fitted to those ``k`` answers and scored,
E_verts mm, on every test window:

* ``weights``: per-vertex skinning weights (``skinning_bounds.fit_weights``);
* ``+ LTI``: those plus a per-vertex linear time-invariant response to the skinning
  frame's acceleration, gravity and angular velocity (``dynamics_bounds``' filter bank,
  per-axis: the class of a modal dynamics module);
* ``+ pose``: plus a linear response to the rotations of the vertex's three
  most-weighted joints relative to their parents (SMPL's pose blend shape class);
* ``+ LTI + pose``: both;
* ``nearest state``: plus, per frame, the mean local residual of the ``--neighbours``
  training frames whose body state is nearest (the rotations, relative to their parents,
  of the joints that carry the garment, now and 3 and 6 frames before: pose, velocity
  and acceleration) — a non-parametric regressor, *nonlinear* in the motion, that can
  win only where a state seen in training recurs;

each at the ridge (of ``--ridges``) that scores best on the test windows: an optimistic
choice, as befits a bound. For reference: body skinning of the draped template, weights
fitted to the test window itself (the fixed-weight floor), and the shipped model as
``animate`` runs it. A curve that keeps falling says more motions per garment would let a
model of that class reach further; a flat one says the class is the limit.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/motion_count_bounds.py
        [--config configs/data/benchmark_cmu.yaml] [--work runs/simulation_spread]
        [--train-windows 16] [--test-windows 6] [--counts 1 2 4 8 16] [--draws 3]
        [--ridges 1 100 10000] [--workers 2] [--types dress skirt ...]
        [--responses diagonal pose diagonal+pose nearest] [--neighbours 5]

Simulations (~20 s each on one core) are saved under ``--work``/motion_count, so an
interrupted run resumes (a sequence the simulator left out is recorded there too, with
its reason, and not retried); ``--workers`` run them in parallel processes of one thread.
"""

from __future__ import annotations

import argparse
import dataclasses
import io
import os
import sys
import time
from multiprocessing import get_context
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "benchmarks"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

from dynamics_bounds import (  # noqa: E402
    Sequence,
    blended_frames,
    fit_response,
    local_rotations,
    with_response,
)
from simulation_spread import chosen_plans, simulate_starts  # noqa: E402
from skinning_bounds import fit_weights, vertex_error_mm  # noqa: E402

from benchmarks.machine import cpu_model  # noqa: E402
from data_prep.config import DataConfig  # noqa: E402
from data_prep.drape_worker import drape_and_prepare_garment  # noqa: E402
from data_prep.plan import MotionPlan, SequencePlan, _clip_motions  # noqa: E402
from gnngarment.config import load_config  # noqa: E402
from gnngarment.data.cache import read_garment  # noqa: E402
from gnngarment.io.atomic import atomic_write_bytes  # noqa: E402

#: The per-garment model classes fitted on the training windows, in table order.
RESPONSES = ("diagonal", "pose", "diagonal+pose", "nearest")
RESPONSE_NAMES = {"diagonal": "+ LTI", "pose": "+ pose", "diagonal+pose": "+ LTI + pose",
                  "nearest": "nearest state"}
#: The frames before the current one whose pose the nearest-state regressor also reads.
STATE_LAGS = (0, 3, 6)
#: A joint carries the garment when some vertex's body weight on it exceeds this.
CARRYING_WEIGHT = 0.05


def body_state(sequence: Sequence) -> np.ndarray:
    """``(T, D)`` the body state the nearest-state regressor compares: ``R − I`` of the
    rotations (relative to the parent) of the joints that carry the garment, at each of
    :data:`STATE_LAGS` frames back (the first frame repeated before the start)."""
    carrying = np.flatnonzero(sequence.prior.max(axis=0) > CARRYING_WEIGHT)
    carrying = carrying[carrying != 0]  # the root's global rotation is not a pose
    pose = local_rotations(sequence.transforms)[:, carrying].reshape(len(sequence.target), -1)
    frames = np.arange(len(pose))
    return np.concatenate([pose[np.maximum(frames - lag, 0)] for lag in STATE_LAGS], axis=1)


class NearestState:
    """The nearest-state regressor fitted to ``train`` under ``weights``: the training
    frames' body states (:func:`body_state`, scaled to unit spread) and local residuals,
    computed once for every test sequence it predicts."""

    def __init__(self, train: list[Sequence], weights: np.ndarray, neighbours: int):
        states = np.concatenate([body_state(s) for s in train])
        self.scale = states.std(axis=0) + 1e-6
        self.states = states / self.scale
        self.residuals = np.concatenate([s.local_residual(weights) for s in train])  # (ΣT, N, 3)
        self.weights, self.neighbours = weights, neighbours

    def predict(self, sequence: Sequence) -> np.ndarray:
        """``(T, N, 3)`` ``sequence`` skinned with the weights plus, per frame, the mean
        local residual of the ``neighbours`` training frames of the nearest body state."""
        query = body_state(sequence) / self.scale
        distance = ((query[:, None, :] - self.states[None]) ** 2).sum(-1)          # (T, ΣT)
        nearest = np.argsort(distance, axis=1)[:, :self.neighbours]
        offsets = self.residuals[nearest].mean(axis=1)                              # (T, N, 3)
        carried = np.einsum("tnab,tnb->tna", blended_frames(sequence.transforms, self.weights),
                            offsets)
        return sequence.skinned(self.weights) + carried


def chosen_windows(config: DataConfig, train: int, test: int) -> tuple[list[MotionPlan],
                                                                        list[MotionPlan]]:
    """The first ``train`` windows of the training subjects and ``test`` of the test
    subjects (each list round-robin over its subjects), with as many windows per clip
    as the counts need."""
    per_clip = config.windows_per_clip
    while True:
        clips = _clip_motions(dataclasses.replace(config, windows_per_clip=per_clip))
        chosen = {split: [m for m in clips if m.split == split] for split in ("train", "test")}
        enough = len(chosen["train"]) >= train and len(chosen["test"]) >= test
        if enough or per_clip >= 16:
            return chosen["train"][:train], chosen["test"][:test]
        per_clip += 1


def window_plans(config: DataConfig, windows: list[MotionPlan], types: list[str] | None
                 ) -> tuple[list[SequencePlan], dict[str, list[SequencePlan]]]:
    """The test designs (one per type of ``types``, all when None, on the first test
    body) and, per design's garment, its sequence on each of ``windows``."""
    designs = [p for p in chosen_plans(config, 1, "procedural")
               if types is None or p.design.garment_type in types]
    plans = {d.garment: [dataclasses.replace(d, motion=m, name=f"{d.garment}_{m.name}")
                         for m in windows] for d in designs}
    return designs, plans


def add_window_arguments(parser: argparse.ArgumentParser) -> None:
    """The options that choose the garments and windows, shared by the bounds that run
    on this script's simulations (``contact_bounds``, ``autoregressive_bounds``)."""
    parser.add_argument("--config", type=Path,
                        default=ROOT / "configs/data/benchmark_cmu.yaml")
    parser.add_argument("--work", type=Path, default=ROOT / "runs/simulation_spread")
    parser.add_argument("--train-windows", type=int, default=16)
    parser.add_argument("--test-windows", type=int, default=6)
    parser.add_argument("--types", nargs="+", default=None, help="garment types (default all)")


def draped_window_plans(args: argparse.Namespace) -> tuple[
        DataConfig, list[MotionPlan], list[MotionPlan], list[SequencePlan],
        dict[str, list[SequencePlan]]]:
    """``(config, training windows, test windows, designs, plans)`` of
    :func:`add_window_arguments`' options, for a bound that reads drapes this script made
    in ``--work``: exits with the reason when there is no design or a drape is missing."""
    config = load_config(args.config, DataConfig)
    train_windows, test_windows = chosen_windows(config, args.train_windows, args.test_windows)
    designs, plans = window_plans(config, train_windows + test_windows, args.types)
    if not designs:
        sys.exit(f"error: {args.config}: no test design of types {args.types}")
    missing = [d.garment for d in designs
               if not (args.work / "garments" / f"{d.garment}.npz").is_file()]
    if missing:
        sys.exit(f"error: {args.work}: no drapes of {', '.join(missing)} "
                 "(run motion_count_bounds.py with the same --work first)")
    return config, train_windows, test_windows, designs, plans


def _saved(work: Path, plan: SequencePlan) -> Path:
    return work / "motion_count" / f"{plan.name}.npz"


def _left_out(work: Path, plan: SequencePlan) -> Path:
    """Where the simulator's reason for leaving ``plan`` out is kept, so that a later
    run does not simulate it again."""
    return work / "motion_count" / f"{plan.name}.left_out.txt"


def _simulate(task: tuple[str, SequencePlan, DataConfig]) -> tuple[str, str]:
    """One sequence, saved atomically (a worker process of one thread)."""
    work, plan, config = Path(task[0]), task[1], task[2]
    torch.set_num_threads(1)
    started = time.perf_counter()
    runs = simulate_starts(work, plan, config, {"answer": None})
    if isinstance(runs, str):
        atomic_write_bytes(_left_out(work, plan), runs.encode())
        return plan.name, f"left out: {runs}"
    runs["seconds"] = np.array(time.perf_counter() - started)
    buffer = io.BytesIO()
    np.savez(buffer, **runs)
    atomic_write_bytes(_saved(work, plan), buffer.getvalue())
    return plan.name, f"{time.perf_counter() - started:.0f} s"


def simulate_all(work: Path, plans: list[SequencePlan], config: DataConfig,
                 workers: int) -> None:
    todo = [p for p in plans
            if not _saved(work, p).is_file() and not _left_out(work, p).is_file()]
    (work / "motion_count").mkdir(parents=True, exist_ok=True)
    print(f"{len(plans) - len(todo)} of {len(plans)} sequences already simulated or left "
          f"out by the simulator; {len(todo)} to go on {workers} worker(s)",
          file=sys.stderr, flush=True)
    tasks = [(str(work), p, config) for p in todo]
    def report(results) -> None:
        for done, (name, status) in enumerate(results, 1):
            print(f"  [{done}/{len(todo)}] {name}: {status}", file=sys.stderr, flush=True)

    if workers <= 1:
        report(map(_simulate, tasks))
        return
    with get_context("spawn").Pool(workers) as pool:
        report(pool.imap_unordered(_simulate, tasks))


def load_sequence(work: Path, plan: SequencePlan, config: DataConfig) -> Sequence | None:
    saved = _saved(work, plan)
    if not saved.is_file():
        return None
    garment = read_garment(work, plan.garment)
    with np.load(saved) as stored:
        return Sequence(plan.name, plan.design.garment_type, plan.motion.name,
                        garment.rest_pos, garment.body_weights, stored["joint_transforms"],
                        stored["answer"], config.fps)


def simulated_split(work: Path, group: list[SequencePlan], config: DataConfig,
                    test_names: set[str]) -> tuple[list[tuple[SequencePlan, Sequence]],
                                                   list[tuple[SequencePlan, Sequence]]]:
    """The simulated sequences of ``group`` (those the simulator left out skipped) with
    their plans, split into training and test windows by the test windows' names."""
    loaded = [(p, load_sequence(work, p, config)) for p in group]
    loaded = [(p, s) for p, s in loaded if s is not None]
    return ([(p, s) for p, s in loaded if p.motion.name not in test_names],
            [(p, s) for p, s in loaded if p.motion.name in test_names])


def shipped_model_errors(work: Path, tests: list[tuple[SequencePlan, Sequence]],
                         config: DataConfig) -> list[float]:
    """E_verts (mm) of the shipped model as ``animate`` runs it, per test sequence."""
    from data_prep.bodies import anny_body_model, anny_shape
    from data_prep.plan import planned_motion
    from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
    from gnngarment.inference.animate import animate
    from gnngarment.model.checkpoint import load_model
    from gnngarment.paths import SHIPPED_MODEL

    model = load_model(SHIPPED_MODEL)
    body_model = anny_body_model()
    errors = []
    for plan, sequence in tests:
        shape = anny_shape(plan.body)
        motion = planned_motion(plan.motion, config, body_model, shape)
        garment = read_garment(work, plan.garment)
        body = body_shape_inputs(body_model, shape, model.config.body_vertices)
        frames = body_motion_inputs(body_model, shape, motion, model.config.body_vertices)
        posed = np.asarray(animate(model, garment.rest_pos, garment.faces, body, frames).posed)
        errors.append(vertex_error_mm(posed, sequence.target))
    return errors


def garment_curve(train: list[Sequence], test: list[Sequence], counts: list[int],
                  draws: int, ridges: list[float], seed: int, responses: list[str],
                  neighbours: int) -> list[dict]:
    """One row per (count, draw): mean E_verts (mm) over ``test`` of each fitted class."""
    rng = np.random.default_rng(seed)
    rows = []
    for count in counts:
        if count > len(train):
            continue
        subsets = ([list(range(len(train)))] if count == len(train) else
                   [sorted(rng.choice(len(train), count, replace=False)) for _ in range(draws)])
        for subset in subsets:
            chosen = [train[i] for i in subset]
            weights = fit_weights([s.per_joint for s in chosen], [s.target for s in chosen],
                                  chosen[0].prior)
            row = {"count": count, "weights": float(np.mean(
                [vertex_error_mm(s.skinned(weights), s.target) for s in test]))}
            for response in responses:
                if response == "nearest":
                    regressor = NearestState(chosen, weights, neighbours)
                    row[response] = float(np.mean([vertex_error_mm(regressor.predict(s),
                                                                   s.target) for s in test]))
                    continue
                best = np.inf
                for ridge in ridges:
                    fitted = fit_response(chosen, [weights] * len(chosen), response, ridge)
                    error = float(np.mean([vertex_error_mm(with_response(s, weights, fitted,
                                                                         response), s.target)
                                           for s in test]))
                    best = min(best, error)
                row[response] = best
            rows.append(row)
            print(f"    k={count} {[train[i].motion for i in subset]}: " + ", ".join(
                f"{key} {value:.2f}" for key, value in row.items() if key != "count"),
                file=sys.stderr, flush=True)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_window_arguments(parser)
    parser.add_argument("--counts", type=int, nargs="+", default=[1, 2, 4, 8, 16])
    parser.add_argument("--draws", type=int, default=3,
                        help="random training subsets per count (one when it is all of them)")
    parser.add_argument("--ridges", type=float, nargs="+", default=[1.0, 100.0, 10000.0])
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--no-model", action="store_true", help="skip the shipped model's row")
    parser.add_argument("--responses", nargs="+", default=list(RESPONSES), choices=RESPONSES,
                        help="the fitted classes beyond the weights")
    parser.add_argument("--neighbours", type=int, default=5,
                        help="training frames the nearest-state regressor averages")
    args = parser.parse_args()
    torch.set_num_threads(1)
    config = load_config(args.config, DataConfig)
    train_windows, test_windows = chosen_windows(config, args.train_windows, args.test_windows)
    designs, plans = window_plans(config, train_windows + test_windows, args.types)
    if not designs:
        sys.exit(f"error: {args.config}: no test design of types {args.types}")
    print(f"{len(designs)} designs × ({len(train_windows)} training-subject + "
          f"{len(test_windows)} test-subject CMU windows) of {args.config.name}; "
          f"{cpu_model()}, load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores",
          flush=True)
    print("training windows: " + ", ".join(m.name for m in train_windows), flush=True)
    print("test windows: " + ", ".join(m.name for m in test_windows), flush=True)
    for design in designs:
        if not (args.work / "garments" / f"{design.garment}.npz").is_file():
            status = drape_and_prepare_garment((str(args.work), design.design, design.body,
                                                config, "motion_count_bounds"))
            if not status.get("ok"):
                print(f"{design.garment}: drape left out: {status.get('reason', status)}")
                plans.pop(design.garment)
    simulate_all(args.work, [p for group in plans.values() for p in group], config,
                 args.workers)

    names = {m.name for m in test_windows}
    summary = []
    for garment, group in plans.items():
        train_plans, test = simulated_split(args.work, group, config, names)
        train = [s for _, s in train_plans]
        if not train or not test:
            print(f"{garment}: too few simulated sequences ({len(train)} train, {len(test)} "
                  "test)")
            continue
        print(f"{garment}: {len(train)} training and {len(test)} test windows simulated",
              file=sys.stderr, flush=True)
        tests = [s for _, s in test]
        reference = {
            "body skinning": float(np.mean([vertex_error_mm(s.skinned(s.prior), s.target)
                                            for s in tests])),
            "weights (self)": float(np.mean([vertex_error_mm(s.skinned(fit_weights(
                [s.per_joint], [s.target], s.prior)), s.target) for s in tests]))}
        if not args.no_model:
            reference["shipped model"] = float(np.mean(shipped_model_errors(args.work, test,
                                                                            config)))
        rows = garment_curve(train, tests, args.counts, args.draws, args.ridges, seed=0,
                             responses=args.responses, neighbours=args.neighbours)
        summary.append((garment, group[0].design.garment_type, len(train), len(tests),
                        reference, rows))

    print("\nE_verts mm on the test-subject windows (ratio to body skinning of the draped "
          "template); fitted classes: mean over draws, best ridge of "
          + ", ".join(f"{r:g}" for r in args.ridges))
    columns = ["weights", *args.responses]
    print("| garment | train / test windows | body skinning | weights (self) | shipped model | k "
          "| " + " | ".join("weights" if c == "weights" else RESPONSE_NAMES[c]
                            for c in columns) + " |")
    print("|---|---|---|---|---|---|" + "---|" * len(columns))
    for garment, _, trained, tested, reference, rows in summary:
        base = reference["body skinning"]

        def cell(value: float, base: float = base) -> str:
            return f"{value:.2f} ({value / base:.2f}×)"

        for count in sorted({r["count"] for r in rows}):
            chosen = [r for r in rows if r["count"] == count]
            head = (f"| {garment} | {trained} / {tested} | {base:.2f} | "
                    f"{cell(reference['weights (self)'])} | "
                    + (cell(reference["shipped model"]) if "shipped model" in reference
                       else "–") + " |")
            print(head + f" {count} | " + " | ".join(
                cell(float(np.mean([r[c] for r in chosen]))) for c in columns) + " |")
    print("\nAll garments, ratio to body skinning (mean of per-garment ratios):")
    print("| k | " + " | ".join("weights" if c == "weights" else RESPONSE_NAMES[c]
                               for c in columns) + " |")
    print("|---|" + "---|" * len(columns))
    for count in args.counts:
        ratios = {c: [] for c in columns}
        for _, _, _, _, reference, rows in summary:
            chosen = [r for r in rows if r["count"] == count]
            if chosen:
                for c in columns:
                    ratios[c].append(np.mean([r[c] for r in chosen]) / reference["body skinning"])
        if ratios["weights"]:
            print(f"| {count} ({len(ratios['weights'])} garments) | " + " | ".join(
                f"{np.mean(ratios[c]):.2f}×" for c in columns) + " |")
    if summary:
        for key in ("weights (self)", "shipped model"):
            values = [ref[key] / ref["body skinning"] for *_, ref, _ in summary if key in ref]
            if values:
                print(f"{key}: {np.mean(values):.2f}× (mean of per-garment ratios)")


if __name__ == "__main__":
    main()
