"""Which joints a garment's vertices can depend on, by garment type: the weight reach
(:func:`gnngarment.body.joint_reach.reachable_joints`, 0.2 m, the shipped model's
``weight_reach`` and ``motion_reach``) over every draped garment of a build.

The spurious-correlation test rotates a joint that should not move the garment. With
the reach, the shipped model cannot depend on a joint out of reach, so a test joint out
of reach reads 0 by construction; this table is what a test joint *within* reach could
be chosen from (issue 37 §4). Printed per type: each reachable joint with the share of
vertices that reach it (mean over garments) / the share of garments in which any
vertex does.

    .venv/bin/python benchmarks/reachable_joints.py [--data data/benchmark_cmu] [--reach 0.2]
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

from gnngarment.body.joint_reach import reachable_joints  # noqa: E402
from gnngarment.body.skeleton import JOINT_NAMES  # noqa: E402
from gnngarment.data.cache import read_garment  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT / "data/benchmark_cmu")
    parser.add_argument("--reach", type=float, default=0.2, help="metres")
    args = parser.parse_args()
    shares: dict[str, list[np.ndarray]] = {}
    for path in sorted((args.data / "garments").glob("*.npz")):
        garment = read_garment(args.data, path.stem)
        if garment.body_weights is None or garment.joint_distances is None:
            continue
        reachable = reachable_joints(torch.from_numpy(garment.rest_pos),
                                     torch.from_numpy(garment.body_weights),
                                     torch.from_numpy(garment.joint_distances), args.reach)
        shares.setdefault(garment.garment_type, []).append(reachable.numpy().mean(axis=0))
    if not shares:
        sys.exit(f"error: {args.data}/garments: no draped garment with body weights")
    print(f"| garment type | garments | joints within {args.reach:.2f} m: % of vertices "
          "(mean) / % of garments |")
    print("|---|---|---|")
    for garment_type, rows in sorted(shares.items()):
        table = np.array(rows)
        mean, anywhere = table.mean(axis=0), (table > 0).mean(axis=0)
        cells = ", ".join(f"{JOINT_NAMES[j]} {100 * mean[j]:.0f}/{100 * anywhere[j]:.0f}"
                          for j in np.argsort(-mean) if anywhere[j] > 0)
        print(f"| {garment_type} | {len(rows)} | {cells} |")


if __name__ == "__main__":
    main()
