"""Skinning weight on far joints (issue 12 §3), per model, on a split of a synthetic cache.

For every sequence of the split: the largest share of any vertex's skinning weight on
joints whose body region lies more than 20 cm farther from the vertex than its nearest
body part (:func:`gnngarment.evaluation.metrics.far_joint_weight`), for body skinning
(the cache's transferred weights) and each checkpoint; prints the max and mean over the
split. Such weight drags a garment after a distant limb on real mocap (the earlier
shipped model put ~30 % of trousers' weight on the neck, collars and head).

    .venv/bin/python benchmarks/far_joint_weight.py CHECKPOINT [CHECKPOINT ...]
        [--data data/benchmark] [--split test]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from data_prep.posed_bodies import synthetic_body_meshes, synthetic_skinning_weights  # noqa: E402
from gnngarment.data import PreparedDataset  # noqa: E402
from gnngarment.evaluation.evaluate import predict  # noqa: E402
from gnngarment.evaluation.metrics import far_joint_weight  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoints", nargs="+", type=Path)
    parser.add_argument("--data", default="data/benchmark")
    parser.add_argument("--split", default="test")
    args = parser.parse_args()
    torch.set_num_threads(1)
    meshes = synthetic_body_meshes(args.data)
    skinning = synthetic_skinning_weights(args.data)
    if skinning is None:
        raise SystemExit(f"{args.data}: not a synthetic cache (no body model to take regions from)")
    models = {str(path): load_model(path) for path in args.checkpoints}
    dataset = PreparedDataset(args.data, args.split, max(m.config.window for m in models.values()))
    found: dict[str, list[dict[str, float]]] = {}
    for name in dataset.sequence_names:
        mesh = meshes(name)
        if mesh is None:
            continue
        rest = dataset.garment_of(name).pair.rest_pos.numpy()
        body = mesh[0][0]  # frame 0: every procedural motion starts in the rest pose
        body_weights = dataset.garment_of(name).pair.body_weights.numpy()
        found.setdefault("body skinning", []).append(
            far_joint_weight(body_weights, rest, body, skinning))
        for label, model in models.items():
            weights = predict(model, dataset, name, return_weights=True)[1]
            found.setdefault(label, []).append(far_joint_weight(weights, rest, body, skinning))
    for label, values in found.items():
        print(f"{label}: far weight max {100 * max(v['max'] for v in values):.1f} %, mean "
              f"{100 * np.mean([v['mean'] for v in values]):.2f} % over {len(values)} "
              f"sequences ({args.data}, {args.split})")


if __name__ == "__main__":
    main()
