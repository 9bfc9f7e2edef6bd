"""How far per-vertex skinning weights alone can go: bounds for any model whose motion-
independent part is linear blend skinning of the draped template.

For every sequence of a split (default: the benchmark's test split), E_verts (mm, mean
per-vertex distance to the simulated garment over all frames) of:

* ``body skinning``: the draped template skinned with the body's transferred weights
  (the baseline of docs/results.md);
* ``fitted to itself``: per-vertex weights fitted to *that sequence's own* simulated
  frames (non-negative least squares, rows summing to one). No model can know these
  without seeing the answer: it is the lowest error any fixed weights reach on it.

Then, for garment–body pairs of the training split that were simulated with two or more
motions, weights fitted to the pair's *other* motions and evaluated on its first one —
what a model that had learned this very garment perfectly from other motions could
do with fixed weights. ``--regularisation λ ...`` pulls the fit towards the body weights
(``λ ‖w − w_body‖²`` per vertex, positions in metres); λ = 0 is the plain fit.

    .venv/bin/python benchmarks/skinning_bounds.py [--data data/benchmark] [--split test]
        [--pairs 24] [--regularisation 0 0.1 0.3 1 3]

Pure numpy/scipy; ~20 s for the defaults on one core.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
from scipy.optimize import nnls

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from gnngarment.data import PreparedDataset  # noqa: E402
from gnngarment.evaluation.metrics import vertex_error  # noqa: E402

#: Weight of the "rows sum to one" equation against the position residuals (metres):
#: large enough that fitted rows sum to one within ~1e-3.
SUM_TO_ONE_WEIGHT = 10.0


def joint_positions(rest: np.ndarray, transforms: np.ndarray) -> np.ndarray:
    """Every rest vertex moved rigidly by every joint.

    Shapes: rest ``(N, 3)`` metres, transforms ``(T, J, 4, 4)`` → ``(T, N, J, 3)``.
    Linear blend skinning with weights ``w (N, J)`` is :func:`blend`.
    """
    homogeneous = np.concatenate([rest, np.ones((len(rest), 1))], axis=1)
    return np.einsum("tjab,nb->tnja", transforms, homogeneous)[..., :3]


def blend(per_joint: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Linear blend skinning from :func:`joint_positions`: ``(T, N, J, 3)`` blended by
    ``(N, J)`` weights → ``(T, N, 3)`` (the per-joint form the fit needs; the package's
    :func:`gnngarment.body.skinning.skin` gives the same from transforms)."""
    return np.einsum("tnja,nj->tna", per_joint, weights)


def vertex_error_mm(posed: np.ndarray, target: np.ndarray) -> float:
    """E_verts (mm) over all frames of ``(T, N, 3)`` arrays in metres (the evaluation's
    :func:`~gnngarment.evaluation.metrics.vertex_error`)."""
    return 1000.0 * float(vertex_error(posed, target).mean())


def fit_weights(per_joint: list[np.ndarray], targets: list[np.ndarray], prior: np.ndarray,
                regularisation: float = 0.0) -> np.ndarray:
    """Per-vertex skinning weights that best reproduce the target frames.

    Minimises ``Σ_t ‖Σ_j w_j p_tj − y_t‖² + λ ‖w − prior‖²`` over ``w ≥ 0`` with
    ``Σ_j w_j = 1`` (a heavily weighted equation), one vertex at a time.

    Shapes: per_joint and targets lists of ``(T_k, N, J, 3)`` / ``(T_k, N, 3)`` (metres),
    prior ``(N, J)`` → ``(N, J)``.
    """
    count, joints = prior.shape
    weights = np.zeros_like(prior)
    scale = np.sqrt(regularisation)
    for vertex in range(count):
        rows = [p[:, vertex].transpose(0, 2, 1).reshape(-1, joints) for p in per_joint]
        values = [y[:, vertex].reshape(-1) for y in targets]
        rows.append(np.full((1, joints), SUM_TO_ONE_WEIGHT))
        values.append(np.array([SUM_TO_ONE_WEIGHT]))
        if regularisation > 0:
            rows.append(scale * np.eye(joints))
            values.append(scale * prior[vertex])
        weights[vertex] = nnls(np.vstack(rows), np.concatenate(values), maxiter=50 * joints)[0]
    return weights


def _sequence_arrays(dataset: PreparedDataset, name: str) -> tuple[np.ndarray, np.ndarray]:
    garment = dataset.garment_of(name)
    sequence = dataset.sequence(name)
    rest = garment.pair.rest_pos.numpy().astype(np.float64)
    return (joint_positions(rest, sequence.joint_transforms.astype(np.float64)),
            sequence.positions.astype(np.float64))


def bounds_on_split(dataset: PreparedDataset) -> list[dict]:
    """Body skinning and weights fitted to the sequence itself, per sequence."""
    rows = []
    for name in dataset.sequence_names:
        garment = dataset.garment_of(name)
        prior = garment.pair.body_weights.numpy().astype(np.float64)
        per_joint, target = _sequence_arrays(dataset, name)
        fitted = fit_weights([per_joint], [target], prior)
        rows.append({"sequence": name, "type": garment.garment_type,
                     "body skinning": vertex_error_mm(blend(per_joint, prior), target),
                     "fitted to itself": vertex_error_mm(blend(per_joint, fitted), target)})
        print(f"  {name}: {rows[-1]['body skinning']:.2f} / {rows[-1]['fitted to itself']:.2f}",
              file=sys.stderr, flush=True)
    return rows


def transfer_bounds(dataset: PreparedDataset, pairs: int,
                    regularisations: list[float]) -> list[dict]:
    """Weights fitted to a pair's other motions, evaluated on its first motion."""
    by_pair: dict[tuple[str, str], list[str]] = defaultdict(list)
    for name in dataset.sequence_names:
        info = dataset.manifest["sequences"][name]
        by_pair[(info["garment"], info["body"])].append(name)
    chosen = [names for names in by_pair.values() if len(names) >= 2][:pairs]
    rows = []
    for names in chosen:
        garment = dataset.garment_of(names[0])
        prior = garment.pair.body_weights.numpy().astype(np.float64)
        held_joints, held_target = _sequence_arrays(dataset, names[0])
        others = [_sequence_arrays(dataset, name) for name in names[1:]]
        row = {"sequence": names[0], "type": garment.garment_type, "fitted on": len(others),
               "body skinning": vertex_error_mm(blend(held_joints, prior), held_target)}
        for regularisation in regularisations:
            fitted = fit_weights([p for p, _ in others], [y for _, y in others], prior,
                                 regularisation)
            row[f"λ={regularisation:g}"] = vertex_error_mm(blend(held_joints, fitted), held_target)
        rows.append(row)
        print(f"  {names[0]}: " + ", ".join(f"{k} {v:.2f}" for k, v in row.items()
                                           if isinstance(v, float)), file=sys.stderr, flush=True)
    return rows


def _table(rows: list[dict], columns: list[str]) -> None:
    print("| type | sequences | " + " | ".join(f"{c} mm" for c in columns) + " |")
    print("|---|---|" + "---|" * len(columns))
    types = sorted({row["type"] for row in rows})
    for kind in [*types, "all"]:
        chosen = [row for row in rows if kind in ("all", row["type"])]
        means = [np.mean([row[c] for row in chosen]) for c in columns]
        print(f"| {kind} | {len(chosen)} | " + " | ".join(f"{m:.2f}" for m in means) + " |")
    base = np.mean([row[columns[0]] for row in rows])
    print("ratio to " + columns[0] + ": " + ", ".join(
        f"{c} {np.mean([row[c] for row in rows]) / base:.2f}x" for c in columns[1:]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT / "data" / "benchmark")
    parser.add_argument("--split", default="test")
    parser.add_argument("--pairs", type=int, default=24,
                        help="training pairs with two or more motions to fit and hold out")
    parser.add_argument("--regularisation", type=float, nargs="+", default=[0, 0.1, 0.3, 1, 3])
    args = parser.parse_args()
    if not (args.data / "manifest.json").is_file():
        print(f"{args.data}: no prepared cache (build it with `gnngarment prepare`)",
              file=sys.stderr)
        raise SystemExit(2)
    evaluated = PreparedDataset(args.data, args.split, 1)
    print(f"## {args.split} split of {args.data}: weights fitted to each sequence itself")
    _table(bounds_on_split(evaluated), ["body skinning", "fitted to itself"])
    training = PreparedDataset(args.data, "train", 1)
    print(f"\n## train split of {args.data}: weights fitted to the pair's other motions, "
          "evaluated on its first")
    rows = transfer_bounds(training, args.pairs, args.regularisation)
    _table(rows, ["body skinning", *[f"λ={r:g}" for r in args.regularisation]])


if __name__ == "__main__":
    main()
