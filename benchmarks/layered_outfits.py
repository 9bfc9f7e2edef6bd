"""Layered outfits against Newton: the outfit simulated in one scene is the answer.

The outfits are those a synthetic build simulates with ``outfits`` in its config
(default ``configs/data/benchmark_cmu.yaml``, ``outfits: 6``; :func:`data_prep.plan.plan_outfits`):
on each test body a test bottom (trousers, skirt) under a test top (T-shirt, top), on
every held-out motion of the bottom's test sequences (the procedural one and its CMU
windows). Newton simulates both garments in one scene with its cloth self-contact
(:mod:`data_prep.outfit_worker`), from their drapes with the top first moved 1.5× the
self-contact distance outside the bottom. A build that has the sequences simulates
only the outfits::

    gnngarment prepare --config configs/data/benchmark_cmu.yaml
    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/layered_outfits.py [--data data/benchmark_cmu]

It prints per outfit and their mean (:func:`gnngarment.evaluation.outfits.evaluate_outfit`,
as ``gnngarment evaluate`` does): each garment's E_verts (mm, against Newton's outfit)
as an outfit and, for the top, alone and by body skinning; inter-garment penetration (%
of the top's vertices behind the bottom) of Newton's answer, of our raw output and after
resolution. Issue 40's bars: penetration after resolution ≤ Newton's own; the top's
E_verts as an outfit within +2 % of resolving it alone.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.machine import cpu_model  # noqa: E402
from data_prep.posed_bodies import synthetic_body_inputs  # noqa: E402
from gnngarment.data.dataset import PreparedDataset  # noqa: E402
from gnngarment.evaluation.outfits import evaluate_outfit, outfit_names  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT / "data/benchmark_cmu")
    parser.add_argument("--split", default="test")
    parser.add_argument("--checkpoint", type=Path, default=SHIPPED_MODEL)
    args = parser.parse_args()
    torch.set_num_threads(1)
    model = load_model(args.checkpoint)
    dataset = PreparedDataset(args.data, args.split, model.config.window)
    names = outfit_names(dataset)
    if not names:
        sys.exit(f"error: {args.data}: no outfits in split '{args.split}' (build it with "
                 "`outfits` in its config)")
    planned = dataset.manifest.get("config", {}).get("outfits", len(names))
    print(f"{args.checkpoint.name}; {len(names)} outfit sequences of {args.data} (of "
          f"{planned} planned pairs, each on its bottom's held-out motions; build_report.json "
          f"lists those Newton's gates left out); {cpu_model()}, load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print("| outfit | through: Newton | ours raw | ours resolved | largest push mm "
          "| bottom E_verts: ours / body skinning | top E_verts: outfit / alone / body "
          "skinning |")
    print("|---|---|---|---|---|---|---|")
    body_inputs = synthetic_body_inputs(args.data)
    rows = []
    for name in names:
        row = evaluate_outfit(model, dataset, name, body_inputs)
        if row is None:
            print(f"| {name} | the body could not be re-posed |")
            continue
        rows.append(row)
        print(f"| {name} | {row['through_simulation_pct']:.2f} % | {row['through_raw_pct']:.2f} % "
              f"| {row['through_resolved_pct']:.2f} % | {row['largest_push_mm']:.1f} | "
              f"{row['inner_e_verts_mm']:.1f} / {row['inner_skinning_mm']:.1f} | "
              f"{row['outer_e_verts_mm']:.1f} / {row['outer_alone_e_verts_mm']:.1f} / "
              f"{row['outer_skinning_mm']:.1f} |", flush=True)
    if not rows:
        sys.exit("error: no outfit could be evaluated")
    mean = {key: sum(r[key] for r in rows) / len(rows) for key in rows[0]}
    print(f"| **mean of {len(rows)}** | {mean['through_simulation_pct']:.2f} % | "
          f"{mean['through_raw_pct']:.2f} % | {mean['through_resolved_pct']:.2f} % | "
          f"{mean['largest_push_mm']:.1f} | {mean['inner_e_verts_mm']:.1f} / "
          f"{mean['inner_skinning_mm']:.1f} | {mean['outer_e_verts_mm']:.1f} / "
          f"{mean['outer_alone_e_verts_mm']:.1f} / {mean['outer_skinning_mm']:.1f} |")
    ratio = mean["outer_e_verts_mm"] / mean["outer_alone_e_verts_mm"] - 1
    print(f"penetration after resolution ≤ Newton's: "
          f"{'yes' if mean['through_resolved_pct'] <= mean['through_simulation_pct'] else 'no'}; "
          f"top as an outfit vs alone: {100 * ratio:+.1f} % (bar ≤ +2 %)")


if __name__ == "__main__":
    main()
