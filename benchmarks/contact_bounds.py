"""Is what the issue's dynamics class leaves a function of the garment's contact with the
moving body? A per-garment nonlinear regressor with and without body-surface-relative
inputs, on the simulations of ``motion_count_bounds.py``.

``motion_count_bounds.py`` found that a per-garment linear response to the skinning
frames' motion and to the pose, fitted to 16 motions, reaches only 0.82× body skinning on
unseen motions, and that a lookup on the joints' state adds nothing; what is left between
that and the chaos floor (about 0.27×, ``simulation_spread.py``) was presumed to be
contact with the moving body surface. This script measures the presumption. For each
garment of ``motion_count_bounds.py`` (its drapes and simulations in ``--work``, made
there first), weights are fitted to all training-subject windows
(``skinning_bounds.fit_weights``) and a small MLP, shared by the garment's vertices, is
fitted to the residual those weights leave (in each vertex's skinning frame), from:

* ``motion``: the vertex's rest position, the linear class's regressors (its skinning
  frame's filtered drive and angular velocity, ``dynamics_bounds``' filter bank, and
  the rotations of its three most-weighted joints) — a *nonlinear* function of what the
  linear class sees;
* ``contact``: the rest position and, at the vertex's skinned position, the offset to
  the nearest posed-body vertex, its distance and the body's velocity there relative to
  the skinned vertex (all in the skinning frame), now and :data:`CONTACT_LAGS` frames
  before;
* ``motion + contact``: both.

Each is scored, E_verts mm, on the test-subject windows after every epoch; the best
epoch is reported (chosen on the test: optimistic, as befits a bound). If ``motion +
contact`` falls well below ``motion``, the body surface carries what the joints' motion
does not, and a model should see it; if not, the presumption is wrong.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/contact_bounds.py
        [--config configs/data/benchmark_cmu.yaml] [--work runs/simulation_spread]
        [--train-windows 16] [--test-windows 6] [--types dress skirt ...]
        [--inputs motion contact motion+contact] [--epochs 8] [--samples 1000000]
        [--workers 2]

Numpy/scipy features, torch for the MLP (one thread); a few minutes per garment and
input set once the simulations exist.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
import torch
from scipy.spatial import cKDTree
from torch import nn

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "benchmarks"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

from dynamics_bounds import Sequence, blended_frames, pose_features  # noqa: E402
from motion_count_bounds import (  # noqa: E402
    add_window_arguments,
    draped_window_plans,
    simulate_all,
    simulated_split,
)
from skinning_bounds import fit_weights, vertex_error_mm  # noqa: E402

from benchmarks.machine import cpu_model  # noqa: E402
from data_prep.bodies import anny_body_model, anny_shape  # noqa: E402
from data_prep.config import DataConfig  # noqa: E402
from data_prep.plan import SequencePlan, planned_motion  # noqa: E402

#: The input sets the regressor is fitted from, in table order.
INPUTS = ("motion", "contact", "motion+contact")
#: Frames before the current one whose contact state the regressor also reads.
CONTACT_LAGS = (0, 3, 6)
#: The MLP's hidden width and depth.
HIDDEN, LAYERS = 128, 2


def posed_body(plan: SequencePlan, config: DataConfig, body_model) -> np.ndarray:
    """``(T, N_b, 3)`` the body's vertices (metres) over ``plan``'s motion, as the
    simulator saw them."""
    shape = anny_shape(plan.body)
    motion = planned_motion(plan.motion, config, body_model, shape)
    with torch.no_grad():
        return body_model.pose(motion, shape).vertices.numpy().astype(np.float64)


def contact_features(sequence: Sequence, weights: np.ndarray, body: np.ndarray,
                     fps: float) -> np.ndarray:
    """``(T, N, 7 · len(CONTACT_LAGS))`` per vertex and frame, in its skinning frame: the
    offset (m) from the skinned vertex to the nearest body vertex, its length, and the
    body's velocity there relative to the skinned vertex's (m/s), at each lag (the first
    frame repeated before the start)."""
    skinned = sequence.skinned(weights)                                        # (T, N, 3)
    frames = blended_frames(sequence.transforms, weights)                      # (T, N, 3, 3)
    body_velocity = np.concatenate([np.zeros_like(body[:1]), np.diff(body, axis=0)]) * fps
    vertex_velocity = np.concatenate([np.zeros_like(skinned[:1]),
                                      np.diff(skinned, axis=0)]) * fps
    offset = np.empty_like(skinned)
    relative = np.empty_like(skinned)
    for t in range(len(skinned)):
        _, nearest = cKDTree(body[t]).query(skinned[t])
        offset[t] = body[t, nearest] - skinned[t]
        relative[t] = body_velocity[t, nearest] - vertex_velocity[t]
    local = np.linalg.solve(frames, np.stack([offset, relative], axis=-1))    # (T, N, 3, 2)
    state = np.concatenate([local[..., 0], np.linalg.norm(offset, axis=-1, keepdims=True),
                            local[..., 1]], axis=-1)                           # (T, N, 7)
    steps = np.arange(len(state))
    return np.concatenate([state[np.maximum(steps - lag, 0)] for lag in CONTACT_LAGS], axis=-1)


def motion_features(sequence: Sequence) -> np.ndarray:
    """``(T, N, 81)`` the linear class's regressors of every vertex: filtered drive and
    angular velocity (6 × 9) and its joints' rotations (27)."""
    filtered = sequence.inputs.reshape(*sequence.inputs.shape[:2], -1)
    return np.concatenate([filtered, pose_features(sequence.transforms, sequence.prior)],
                          axis=-1)


def regressor_inputs(sequence: Sequence, parts: dict[str, np.ndarray], inputs: str
                     ) -> np.ndarray:
    """``(T, N, F)`` float32: the rest position and the parts ``inputs`` names."""
    frames = len(sequence.target)
    chosen = [np.broadcast_to(sequence.rest, (frames, *sequence.rest.shape))]
    chosen += [parts[name] for name in inputs.split("+")]
    return np.concatenate(chosen, axis=-1).astype(np.float32)


def fit_and_score(train: list[np.ndarray], residuals: list[np.ndarray],
                  test: list[tuple[np.ndarray, Sequence]], weights: np.ndarray,
                  epochs: int, samples: int, seed: int) -> list[float]:
    """Fit an MLP from the inputs ``(T, N, F)`` to the local residuals ``(T, N, 3)`` of
    ``train``; E_verts (mm) on every ``test`` sequence's mean after each epoch."""
    generator = torch.Generator().manual_seed(seed)
    x = torch.from_numpy(np.concatenate([a.reshape(-1, a.shape[-1]) for a in train]))
    y = torch.from_numpy(np.concatenate([r.reshape(-1, 3) for r in residuals]).astype(
        np.float32)) * 1000.0                                                  # mm
    mean, scale = x.mean(0), x.std(0) + 1e-6
    layers: list[nn.Module] = []
    width = x.shape[1]
    for _ in range(LAYERS):
        layers += [nn.Linear(width, HIDDEN), nn.SiLU()]
        width = HIDDEN
    torch.manual_seed(seed)
    network = nn.Sequential(*layers, nn.Linear(width, 3))
    steps_per_epoch = max(samples // 4096, 1)
    optimiser = torch.optim.Adam(network.parameters(), lr=1e-3)
    schedule = torch.optim.lr_scheduler.CosineAnnealingLR(optimiser, epochs * steps_per_epoch)
    # Each test sequence's skinning frames and skinned positions, computed once.
    references = [(torch.from_numpy(inputs.reshape(-1, inputs.shape[-1])), inputs.shape[:2],
                   blended_frames(sequence.transforms, weights), sequence.skinned(weights),
                   sequence.target) for inputs, sequence in test]
    errors = []
    for _ in range(epochs):
        network.train()
        for _ in range(steps_per_epoch):
            batch = torch.randint(len(x), (4096,), generator=generator)
            loss = ((network((x[batch] - mean) / scale) - y[batch]) ** 2).mean()
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            schedule.step()
        network.eval()
        scores = []
        with torch.no_grad():
            for flat, shape, frames, skinned, target in references:
                offsets = (network((flat - mean) / scale).numpy().astype(np.float64)
                           / 1000.0).reshape(*shape, 3)
                carried = np.einsum("tnab,tnb->tna", frames, offsets)
                scores.append(vertex_error_mm(skinned + carried, target))
        errors.append(float(np.mean(scores)))
    return errors


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_window_arguments(parser)
    parser.add_argument("--inputs", nargs="+", default=list(INPUTS), choices=INPUTS)
    parser.add_argument("--epochs", type=int, default=8)
    parser.add_argument("--samples", type=int, default=1_000_000,
                        help="training samples (vertex-frames) drawn per epoch")
    parser.add_argument("--workers", type=int, default=1,
                        help="simulation processes, for sequences not yet simulated")
    args = parser.parse_args()
    torch.set_num_threads(1)
    config, train_windows, test_windows, designs, plans = draped_window_plans(args)
    print(f"{len(designs)} designs × ({len(train_windows)} training-subject + "
          f"{len(test_windows)} test-subject CMU windows) of {args.config.name}; "
          f"{cpu_model()}, load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; "
          f"MLP {LAYERS}×{HIDDEN}, {args.epochs} epochs of {args.samples:,} samples",
          flush=True)
    simulate_all(args.work, [p for group in plans.values() for p in group], config,
                 args.workers)
    body_model = anny_body_model()
    test_names = {m.name for m in test_windows}
    rows = []
    for garment, group in plans.items():
        started = time.perf_counter()
        train, test = simulated_split(args.work, group, config, test_names)
        if len(train) < 2 or not test:
            print(f"{garment}: too few simulated sequences ({len(train)} train, "
                  f"{len(test)} test)", flush=True)
            continue
        weights = fit_weights([s.per_joint for _, s in train], [s.target for _, s in train],
                              train[0][1].prior)
        parts = {}
        for plan, sequence in train + test:
            parts[plan.name] = {
                "motion": motion_features(sequence),
                "contact": contact_features(sequence, weights,
                                            posed_body(plan, config, body_model), config.fps)}
        row = {"garment": garment, "type": group[0].design.garment_type,
               "windows": f"{len(train)} / {len(test)}",
               "body skinning": float(np.mean([vertex_error_mm(s.skinned(s.prior), s.target)
                                               for _, s in test])),
               "weights": float(np.mean([vertex_error_mm(s.skinned(weights), s.target)
                                         for _, s in test]))}
        residuals = [s.local_residual(weights) for _, s in train]
        for inputs in args.inputs:
            curve = fit_and_score(
                [regressor_inputs(s, parts[p.name], inputs) for p, s in train], residuals,
                [(regressor_inputs(s, parts[p.name], inputs), s) for p, s in test], weights,
                args.epochs, args.samples, seed=0)
            row[inputs] = min(curve)
            print(f"  {garment} {inputs}: per epoch " + " ".join(f"{e:.2f}" for e in curve),
                  file=sys.stderr, flush=True)
        rows.append(row)
        print(f"{garment}: " + ", ".join(f"{k} {v:.2f}" for k, v in row.items()
                                         if isinstance(v, float))
              + f" ({time.perf_counter() - started:.0f} s)", flush=True)

    columns = ["weights", *args.inputs]
    print("\nE_verts mm on the test-subject windows (ratio to body skinning of the draped "
          "template); MLPs at their best epoch")
    print("| garment | train / test windows | body skinning | "
          + " | ".join(f"weights + MLP({c})" if c != "weights" else "weights"
                       for c in columns) + " |")
    print("|---|---|---|" + "---|" * len(columns))
    for row in rows:
        base = row["body skinning"]
        print(f"| {row['garment']} | {row['windows']} | {base:.2f} | " + " | ".join(
            f"{row[c]:.2f} ({row[c] / base:.2f}×)" for c in columns) + " |")
    if rows:
        print("| mean of ratios | | | " + " | ".join(
            f"{np.mean([r[c] / r['body skinning'] for r in rows]):.2f}×" for c in columns)
            + " |")


if __name__ == "__main__":
    main()
