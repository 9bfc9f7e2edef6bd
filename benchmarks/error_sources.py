"""Where a model's error on held-out garments comes from: skinning weights or blend shapes.

For every sequence of a split, E_verts (mm, mean per-vertex distance to the simulated
garment over all frames) of:

* ``full``: the model's prediction ``skin(T + B, W)``;
* ``weights only``: the predicted weights without blend shapes, ``skin(T, W)``;
* ``LBS + B``: body-transferred weights with the predicted blend shapes, ``skin(T + B, W_body)``;
* ``LBS``: the body-skinning baseline ``skin(T, W_body)``;

and the mean blend-shape magnitude ``|B|``. ``weights only`` ≈ ``LBS`` and ``full`` ≫
``LBS`` means the blend shapes hurt; ``LBS + B`` < ``LBS`` means they help.

    .venv/bin/python benchmarks/error_sources.py CHECKPOINT [CHECKPOINT ...]
        [--data data/demo] [--split test]
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

from gnngarment.body.skinning import skin  # noqa: E402
from gnngarment.data import PreparedDataset  # noqa: E402
from gnngarment.data.cache import read_garment  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.training.trainer import TrainingStep  # noqa: E402


def error_sources(checkpoint: Path, data: Path, split: str) -> list[dict]:
    """One row per sequence of ``split``: the four errors (mm) and |B| (mm)."""
    model = load_model(checkpoint)
    dataset = PreparedDataset(data, split, model.config.window)
    rows = []
    for name in dataset.sequence_names:
        frames = dataset.frame_counts[name]
        batch = dataset.batch([(name, np.arange(frames))])
        with torch.no_grad():
            output = TrainingStep(model)(batch)
        garment = read_garment(data, dataset.manifest["sequences"][name]["garment"])
        rest = torch.from_numpy(garment.rest_pos).float()
        count = len(rest)
        rest = rest.expand(frames, count, 3)
        weights = output.weights.view(frames, count, 24)
        blend = output.blend_shapes.view(frames, count, 3)
        transforms = batch.joint_transforms[0]
        target = batch.target.view(frames, count, 3)
        body_weights = torch.from_numpy(garment.body_weights).float().expand(frames, count, 24)

        def millimetres(posed: torch.Tensor, target: torch.Tensor = target) -> float:
            return 1000 * float((posed - target).norm(dim=-1).mean())

        rows.append({
            "sequence": name, "type": dataset.manifest["sequences"][name]["garment_type"],
            "full": millimetres(output.posed.view(frames, count, 3)),
            "weights only": millimetres(skin(rest, None, weights, transforms)),
            "LBS + B": millimetres(skin(rest, blend, body_weights, transforms)),
            "LBS": millimetres(skin(rest, None, body_weights, transforms)),
            "|B|": 1000 * float(blend.norm(dim=-1).mean())})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("checkpoints", type=Path, nargs="+")
    parser.add_argument("--data", type=Path, default=ROOT / "data" / "demo")
    parser.add_argument("--split", default="test")
    args = parser.parse_args()
    torch.set_num_threads(1)
    columns = ("full", "weights only", "LBS + B", "LBS", "|B|")
    print("| checkpoint | sequence | " + " | ".join(f"{c} mm" for c in columns) + " |")
    print("|---|---|" + "---|" * len(columns))
    for checkpoint in args.checkpoints:
        label = f"{checkpoint.parent.name}/{checkpoint.name}"
        for row in error_sources(checkpoint, args.data, args.split):
            print(f"| {label} | {row['sequence']} | "
                  + " | ".join(f"{row[c]:.1f}" for c in columns) + " |")


if __name__ == "__main__":
    main()
