"""Does the cloth's own state carry what per-frame regressors of the motion miss? A
per-garment *autoregressive* regressor, rolled out on unseen motions, on the simulations
of ``motion_count_bounds.py``.

``contact_bounds.py`` found that a per-garment MLP from the motion and from the
body-surface state, fitted to 16 motions of the garment, reaches 0.79× body skinning on
unseen motions, far from the chaos floor (about 0.27×, ``simulation_spread.py``); the
presumption it left is that what is missing is the cloth's own state (which side of a
leg a hem fell on, how fast it still swings), which a function of the motion cannot
see and a model that feeds its own past output back (HOOD, ContourCraft, MeshGraphNets)
carries. This script measures that before anything is built. For each garment of
``motion_count_bounds.py`` (its drapes and simulations in ``--work``), weights are
fitted to the training-subject windows (``skinning_bounds.fit_weights``), and an MLP
shared by the vertices (``contact_bounds``' width and depth) predicts the local residual
``r_t`` those weights leave (mm, in the vertex's skinning frame) from:

* ``per-frame``: ``contact_bounds``' best input set (rest position, the linear class's
  motion regressors, the body-surface state at lags 0/3/6) — the reference, re-measured;
* ``+ own state``: plus the garment's own state one and two frames back — ``r_{t−1}``,
  ``r_{t−1} − r_{t−2}`` and the mean of ``r_{t−1}`` over the vertex's mesh neighbours
  minus its own (the one-ring coupling that lets a neighbourhood move together); the
  network predicts the change from ``r_{t−1}``;
* ``+ own state + cloth contact``: plus the body surface seen from where the cloth *was*
  (the offset, distance and relative velocity from the garment vertex's position at
  ``t−1`` to the nearest posed-body vertex at ``t``), rather than from the skinned
  position.

The state inputs are trained with the true past plus Gaussian noise of ``--noise`` mm
(MeshGraphNets' remedy for the drift of rolled-out models: the network learns to pull a
perturbed state back), and scored by **rolling out** each test-subject window from its
first two true frames (the drape: windows start from the rest pose), feeding the model's
own predictions back — as it would run. E_verts mm after each epoch; the best epoch and
noise are reported (chosen on the test: optimistic, as befits a bound). If ``+ own
state`` falls well below ``per-frame``, an autoregressive model is the lever the issue's
≤ 0.7× needs; if not, not even a garment's own 16 motions teach a per-vertex recurrence
what a simulator knows.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/autoregressive_bounds.py
        [--config configs/data/benchmark_cmu.yaml] [--work runs/simulation_spread]
        [--train-windows 16] [--test-windows 6] [--types dress skirt ...]
        [--inputs per-frame own-state own-state+cloth] [--noise 1 3] [--epochs 6]
        [--samples 500000]

Numpy/scipy features, torch for the MLP (one thread); a few minutes per garment and
input set once the simulations exist (``motion_count_bounds.py --workers 2`` makes them).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import torch
from scipy.spatial import cKDTree
from torch import nn

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "benchmarks"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

from contact_bounds import (  # noqa: E402
    HIDDEN,
    LAYERS,
    contact_features,
    motion_features,
    posed_body,
    regressor_inputs,
)
from dynamics_bounds import Sequence, blended_frames  # noqa: E402
from motion_count_bounds import (  # noqa: E402
    add_window_arguments,
    draped_window_plans,
    simulated_split,
)
from skinning_bounds import fit_weights, vertex_error_mm  # noqa: E402

from benchmarks.machine import cpu_model  # noqa: E402
from data_prep.bodies import anny_body_model  # noqa: E402
from gnngarment.data.cache import read_garment  # noqa: E402
from gnngarment.geometry.graph import adjacency_matrix, edge_index_from_faces  # noqa: E402

#: The input sets, in table order.
INPUTS = ("per-frame", "own-state", "own-state+cloth")
INPUT_NAMES = {"per-frame": "per-frame MLP (motion + contact)",
               "own-state": "rolled out, + own state",
               "own-state+cloth": "rolled out, + own state + cloth contact"}
#: A garment with fewer simulated training windows is left out of the table (the
#: jumpsuit, whose CMU windows mostly fail Newton's stretch gate).
FEWEST_TRAINING_WINDOWS = 4
#: Training rows per optimiser step.
BATCH = 4096


def neighbour_mean(faces: np.ndarray, vertices: int) -> tuple[sp.csr_matrix, np.ndarray]:
    """``(N, N)`` the row-normalised one-ring adjacency (an isolated vertex averages
    itself) and ``(N,)`` each vertex's neighbour count."""
    adjacency = adjacency_matrix(edge_index_from_faces(faces, vertices), vertices)
    adjacency = adjacency.astype(np.float64) + sp.diags(
        (np.asarray(adjacency.sum(axis=1)).ravel() == 0).astype(np.float64))
    degree = np.asarray(adjacency.sum(axis=1)).ravel()
    return sp.diags(1.0 / degree) @ adjacency, degree


def cloth_contact(previous: np.ndarray, before: np.ndarray, body_now: np.ndarray,
                  body_velocity: np.ndarray, frames_now: np.ndarray, fps: float
                  ) -> np.ndarray:
    """``(N, 7)`` for one frame: from the garment's positions ``previous`` (``t − 1``) and
    ``before`` (``t − 2``), ``(N, 3)`` metres, to the nearest vertex of the posed body at
    ``t``: the offset, its length (m) and the body's velocity there relative to the
    garment's (m/s), in the skinning frames ``frames_now`` ``(N, 3, 3)`` at ``t``."""
    _, nearest = cKDTree(body_now).query(previous)
    offset = body_now[nearest] - previous
    relative = body_velocity[nearest] - (previous - before) * fps
    local = np.linalg.solve(frames_now, np.stack([offset, relative], axis=-1))
    return np.concatenate([local[..., 0], np.linalg.norm(offset, axis=-1, keepdims=True),
                           local[..., 1]], axis=-1)


class Garment:
    """One garment's arrays for the fits: per sequence the per-frame inputs ``(T, N, F)``,
    the local residuals ``(T, N, 3)`` mm, the skinning frames and skinned positions, the
    posed body and (for training sequences) the cloth contact of the true past."""

    def __init__(self, sequences: list[Sequence], bodies: list[np.ndarray],
                 parts: list[dict[str, np.ndarray]], weights: np.ndarray,
                 mean: sp.csr_matrix, degree: np.ndarray, fps: float):
        self.weights, self.mean, self.degree, self.fps = weights, mean, degree, fps
        self.items = []
        for sequence, body, part in zip(sequences, bodies, parts, strict=True):
            frames = blended_frames(sequence.transforms, weights)
            residual = sequence.local_residual(weights) * 1000.0
            velocity = np.concatenate([np.zeros_like(body[:1]), np.diff(body, axis=0)]) * fps
            self.items.append({
                "sequence": sequence, "body": body, "body velocity": velocity,
                "frames": frames, "skinned": sequence.skinned(weights),
                "inputs": regressor_inputs(sequence, part, "motion+contact"),
                "residual": residual.astype(np.float32)})

    def true_cloth_contact(self, item: dict) -> np.ndarray:
        """``(T, N, 7)`` :func:`cloth_contact` of the simulated past at every frame (the
        first frames repeat the first position)."""
        target = item["sequence"].target
        steps = np.arange(len(target))
        return np.stack([cloth_contact(target[max(t - 1, 0)], target[max(t - 2, 0)],
                                       item["body"][t], item["body velocity"][t],
                                       item["frames"][t], self.fps)
                         for t in steps]).astype(np.float32)


def training_rows(garment: Garment, inputs: str) -> dict[str, torch.Tensor]:
    """The training rows (frames ``t ≥ 2`` of every training sequence, all vertices):
    per-frame inputs, the clean state ``r_{t−1}``, ``r_{t−2}``, the neighbour mean of
    ``r_{t−1}``, the neighbour counts, the cloth contact, and the target ``r_t``."""
    rows: dict[str, list[np.ndarray]] = {k: [] for k in
                                         ("static", "previous", "before", "around", "target",
                                          "degree", "cloth")}
    for item in garment.items:
        residual = item["residual"]
        around = np.stack([garment.mean @ frame for frame in residual]).astype(np.float32)
        frames = len(residual)
        rows["static"].append(item["inputs"][2:].reshape(-1, item["inputs"].shape[-1]))
        rows["previous"].append(residual[1:frames - 1].reshape(-1, 3))
        rows["before"].append(residual[:frames - 2].reshape(-1, 3))
        rows["around"].append(around[1:frames - 1].reshape(-1, 3))
        rows["target"].append(residual[2:].reshape(-1, 3))
        rows["degree"].append(np.tile(garment.degree, frames - 2).astype(np.float32))
        if inputs == "own-state+cloth":
            rows["cloth"].append(garment.true_cloth_contact(item)[2:].reshape(-1, 7))
    return {k: torch.from_numpy(np.concatenate(v)) for k, v in rows.items() if v}


def state_features(previous: torch.Tensor, before: torch.Tensor, around: torch.Tensor
                   ) -> torch.Tensor:
    """``(R, 9)`` ``r_{t−1}``, ``r_{t−1} − r_{t−2}`` and the one-ring mean minus own."""
    return torch.cat([previous, previous - before, around - previous], dim=1)


def network_for(width: int, seed: int) -> nn.Sequential:
    torch.manual_seed(seed)
    layers: list[nn.Module] = []
    for _ in range(LAYERS):
        layers += [nn.Linear(width, HIDDEN), nn.SiLU()]
        width = HIDDEN
    return nn.Sequential(*layers, nn.Linear(width, 3))


def rollout(network: nn.Module, garment: Garment, item: dict, inputs: str,
            mean: torch.Tensor, scale: torch.Tensor) -> np.ndarray:
    """``(T, N, 3)`` metres: the test sequence ``item`` with the residual predicted frame
    by frame from the model's own past (the first two frames true)."""
    residual = item["residual"]
    predicted = [torch.from_numpy(residual[0]), torch.from_numpy(residual[1])]
    positions = [item["skinned"][t] + np.einsum("nab,nb->na", item["frames"][t],
                                                residual[t] / 1000.0) for t in (0, 1)]
    for t in range(2, len(residual)):
        previous, before = predicted[-1], predicted[-2]
        around = torch.from_numpy((garment.mean @ previous.numpy()).astype(np.float32))
        parts = [torch.from_numpy(item["inputs"][t]), state_features(previous, before, around)]
        if inputs == "own-state+cloth":
            parts.append(torch.from_numpy(cloth_contact(
                positions[-1], positions[-2], item["body"][t], item["body velocity"][t],
                item["frames"][t], garment.fps).astype(np.float32)))
        current = previous + network((torch.cat(parts, dim=1) - mean) / scale)
        predicted.append(current)
        positions.append(item["skinned"][t] + np.einsum(
            "nab,nb->na", item["frames"][t], current.numpy().astype(np.float64) / 1000.0))
    return np.stack(positions)


def per_frame_prediction(network: nn.Module, item: dict, mean: torch.Tensor,
                         scale: torch.Tensor) -> np.ndarray:
    """``(T, N, 3)`` metres: the test sequence with the per-frame MLP's residual."""
    flat = torch.from_numpy(item["inputs"].reshape(-1, item["inputs"].shape[-1]))
    offsets = (network((flat - mean) / scale).numpy().astype(np.float64) / 1000.0).reshape(
        *item["inputs"].shape[:2], 3)
    return item["skinned"] + np.einsum("tnab,tnb->tna", item["frames"], offsets)


def fit_and_score(train: Garment, rows: dict[str, torch.Tensor], test: Garment, inputs: str,
                  noise: float, epochs: int, samples: int, seed: int) -> list[float]:
    """Fit the MLP of ``inputs`` on ``train``'s :func:`training_rows` ``rows``; mean
    E_verts (mm) over ``test``'s sequences after each epoch (rolled out where the inputs
    hold the state)."""
    generator = torch.Generator().manual_seed(seed)
    stateful = inputs != "per-frame"
    if stateful:
        clean = [rows["static"], state_features(rows["previous"], rows["before"],
                                                rows["around"])]
        if "cloth" in rows:
            clean.append(rows["cloth"])
        reference = torch.cat(clean, dim=1)
        target_scale = (rows["target"] - rows["previous"]).std(0).mean()
    else:
        reference = rows["static"]
    mean, scale = reference.mean(0), reference.std(0) + 1e-6
    del reference
    network = network_for(len(mean), seed)
    steps_per_epoch = max(samples // BATCH, 1)
    optimiser = torch.optim.Adam(network.parameters(), lr=1e-3)
    schedule = torch.optim.lr_scheduler.CosineAnnealingLR(optimiser, epochs * steps_per_epoch)
    errors = []
    for _ in range(epochs):
        network.train()
        for _ in range(steps_per_epoch):
            batch = torch.randint(len(rows["target"]), (BATCH,), generator=generator)
            target = rows["target"][batch]
            if not stateful:
                loss = ((network((rows["static"][batch] - mean) / scale) - target) ** 2).mean()
            else:
                # Independent noise per vertex: the neighbours' mean noise has variance
                # σ²/degree, drawn directly instead of perturbing whole frames.
                own = torch.randn(BATCH, 3, generator=generator) * noise
                neighbours = (torch.randn(BATCH, 3, generator=generator) * noise
                              / rows["degree"][batch, None].sqrt())
                previous = rows["previous"][batch] + own
                around = rows["around"][batch] + neighbours
                parts = [rows["static"][batch],
                         state_features(previous, rows["before"][batch], around)]
                if "cloth" in rows:
                    parts.append(rows["cloth"][batch])
                change = network((torch.cat(parts, dim=1) - mean) / scale)
                loss = (((previous + change - target) / target_scale) ** 2).mean()
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            schedule.step()
        network.eval()
        with torch.no_grad():
            scores = [vertex_error_mm(
                rollout(network, train, item, inputs, mean, scale) if stateful
                else per_frame_prediction(network, item, mean, scale),
                item["sequence"].target) for item in test.items]
        errors.append(float(np.mean(scores)))
    return errors


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_window_arguments(parser)
    parser.add_argument("--inputs", nargs="+", default=list(INPUTS), choices=INPUTS)
    parser.add_argument("--noise", type=float, nargs="+", default=[1.0, 3.0],
                        help="training noise (mm) on the state inputs; each is fitted")
    parser.add_argument("--epochs", type=int, default=6)
    parser.add_argument("--samples", type=int, default=500_000,
                        help="training rows (vertex-frames) drawn per epoch")
    args = parser.parse_args()
    torch.set_num_threads(1)
    config, train_windows, test_windows, designs, plans = draped_window_plans(args)
    print(f"{len(designs)} designs × ({len(train_windows)} training-subject + "
          f"{len(test_windows)} test-subject CMU windows) of {args.config.name}; "
          f"{cpu_model()}, load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; "
          f"MLP {LAYERS}×{HIDDEN}, {args.epochs} epochs of {args.samples:,} rows, noise "
          + ", ".join(f"{n:g}" for n in args.noise) + " mm", flush=True)
    body_model = anny_body_model()
    test_names = {m.name for m in test_windows}
    rows = []
    for garment_name, group in plans.items():
        started = time.perf_counter()
        train, test = simulated_split(args.work, group, config, test_names)
        if len(train) < FEWEST_TRAINING_WINDOWS or len(test) < 2:
            print(f"{garment_name}: too few simulated sequences ({len(train)} train, "
                  f"{len(test)} test)", flush=True)
            continue
        weights = fit_weights([s.per_joint for _, s in train], [s.target for _, s in train],
                              train[0][1].prior)
        record = read_garment(args.work, garment_name)
        mean, degree = neighbour_mean(record.faces, len(record.rest_pos))

        def arrays(pairs, weights=weights, mean=mean, degree=degree) -> Garment:
            bodies = [posed_body(p, config, body_model) for p, _ in pairs]
            parts = [{"motion": motion_features(s),
                      "contact": contact_features(s, weights, b, config.fps)}
                     for (_, s), b in zip(pairs, bodies, strict=True)]
            return Garment([s for _, s in pairs], bodies, parts, weights, mean, degree,
                           config.fps)

        train_arrays, test_arrays = arrays(train), arrays(test)
        tests = [s for _, s in test]
        row = {"garment": garment_name, "windows": f"{len(train)} / {len(test)}",
               "body skinning": float(np.mean([vertex_error_mm(s.skinned(s.prior), s.target)
                                               for s in tests])),
               "weights": float(np.mean([vertex_error_mm(s.skinned(weights), s.target)
                                         for s in tests]))}
        for inputs in args.inputs:
            best = np.inf
            training = training_rows(train_arrays, inputs)  # shared by every noise level
            for noise in ([0.0] if inputs == "per-frame" else args.noise):
                curve = fit_and_score(train_arrays, training, test_arrays, inputs, noise,
                                      args.epochs, args.samples, seed=0)
                best = min(best, min(curve))
                print(f"  {garment_name} {inputs} noise {noise:g} mm: per epoch "
                      + " ".join(f"{e:.2f}" for e in curve), file=sys.stderr, flush=True)
            row[inputs] = best
        rows.append(row)
        print(f"{garment_name}: " + ", ".join(f"{k} {v:.2f}" for k, v in row.items()
                                              if isinstance(v, float))
              + f" ({time.perf_counter() - started:.0f} s)", flush=True)

    columns = ["weights", *args.inputs]
    print("\nE_verts mm on the test-subject windows (ratio to body skinning of the draped "
          "template); MLPs at their best epoch and noise, stateful ones rolled out")
    print("| garment | train / test windows | body skinning | "
          + " | ".join("weights" if c == "weights" else f"weights + {INPUT_NAMES[c]}"
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
