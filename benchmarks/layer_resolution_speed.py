"""Cost of an outfit's layer resolution per frame, against the network's time per frame.

Two flared skirts worn one over the other on the Anny body walking, ``--vertices`` each
(inner: waist radius 0.17 m, hem 0.28 m, 0.40 m long; outer 0.45 m long, in two cases:
``apart``, 0.185 / 0.31 m, 1.5 cm outside the inner one, and ``close``, 0.175 / 0.30 m,
5 mm outside, a stress case), animated by the shipped model
(``models/gnngarment-small.pt``) with :func:`~gnngarment.inference.outfit.animate_outfit`.
Prints, measured in one run:

* the network's time per frame for the whole outfit (both garments, batch 16);
* the body's collision resolution per frame (both garments, as ``animate`` runs it);
* the layer resolution per frame (the outer skirt out of the inner one by the clearance,
  :func:`~gnngarment.geometry.garment_layers.resolve_layer_collisions` on the exact Warp
  mesh of the inner skirt, refit per frame), best of ``--repeats`` after a warm-up;
* what it did: outer vertices behind the inner skirt per frame in the network's output
  and after resolution (% of the outer skirt), vertices moved, largest push;
* the ratio layer resolution ÷ network per frame.

    .venv/bin/python benchmarks/layer_resolution_speed.py [--vertices 5000]
        [--frames 48] [--repeats 3] [--threads 1]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.collision_resolution_speed import shipped_model_walking  # noqa: E402
from data_prep.garments.skirt import flared_skirt  # noqa: E402
from gnngarment.geometry.garment_layers import (  # noqa: E402
    LayerSettings,
    layer_penetration,
    outward_faces,
    resolve_layer_collisions,
)
from gnngarment.inference.animate import animate  # noqa: E402
from gnngarment.inference.outfit import OutfitGarment, animate_outfit  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402

BATCH = 16
#: (waist radius, hem radius, length) [m] of the inner skirt and, per case, the outer one.
INNER = (0.17, 0.28, 0.40)
OUTER = {"apart": (0.185, 0.31, 0.45), "close": (0.175, 0.30, 0.45)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--vertices", type=int, default=5000, help="per garment")
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=1, help="torch intra-op threads")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    settings = LayerSettings()
    model, body, frames = shipped_model_walking(args.frames)
    count = len(frames.vertices)
    print(f"{SHIPPED_MODEL.name}, Anny 'average' walking, {count} frames, batch {BATCH}, "
          f"torch threads {args.threads} (Warp: one core), best of {args.repeats}; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; clearance "
          f"{1000 * settings.clearance:.1f} mm")
    print("| case | vertices (inner + outer) | network ms/frame | body resolution ms/frame "
          "| layer resolution ms/frame | layers ÷ network | outer behind inner: network "
          "output % (max) | before layer resolution % | after % | moved per frame "
          "| largest push mm |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for case, outer_shape in OUTER.items():
        measure(case, outer_shape, model, body, frames, args, settings)


def measure(case, outer_shape, model, body, frames, args, settings: LayerSettings) -> None:
    count = len(frames.vertices)
    pelvis = body.joints[0]
    outfit = []
    for name, (waist, hem, length) in (("inner", INNER), ("outer", outer_shape)):
        pos, faces = flared_skirt(args.vertices, waist_radius=waist, hem_radius=hem,
                                  length=length, waist_height=float(pelvis[2]) + 0.08, seed=1)
        pos[:, :2] += pelvis[:2]
        outfit.append(OutfitGarment(name, pos, faces))
    result = animate_outfit(model, outfit, body, frames, chunk=BATCH, layer_settings=settings)
    assert result.order == [0, 1], f"order read at rest: {result.order}"
    inner, outer = result.animations
    beneath_faces = outward_faces(inner.rest_pos, outfit[0].faces, body.rest_vertices,
                                  body.faces)
    network = sum(a.seconds["frames"] for a in result.animations) / count
    body_resolution = sum(a.seconds["collisions"] for a in result.animations) / count
    # What the layer resolution was given: the outer skirt (its rest layered) animated and
    # moved out of the body, as animate_outfit runs it.
    unlayered = animate(model, outer.rest_pos, outfit[1].faces, body, frames,
                        chunk=BATCH).posed
    timings = []
    for repeat in range(args.repeats + 1):  # the first round warms up (Warp compiles)
        tic = time.perf_counter()
        _, stats = resolve_layer_collisions(unlayered, outfit[1].faces,
                                                   [(inner.posed, beneath_faces)], settings)
        if repeat:
            timings.append((time.perf_counter() - tic) / count)
    layers = min(timings)
    before = layer_penetration(unlayered, inner.posed, beneath_faces, settings)
    # What users get: the outfit's own output (it resolves the welded mesh: one push per
    # UV-seam copy).
    after = layer_penetration(outer.posed, inner.posed, beneath_faces, settings)
    raw = result.penetration_raw[1]
    print(f"| {case} | {len(outfit[0].pos)} + {len(outfit[1].pos)} | {1000 * network:.1f} "
          f"| {1000 * body_resolution:.2f} | {1000 * layers:.2f} | {layers / network:.3f} "
          f"| {100 * raw.mean():.2f} ({100 * raw.max():.2f}) | {100 * before.mean():.2f} "
          f"| {100 * after.mean():.3f} | {stats.moved.mean():.0f} "
          f"| {1000 * stats.max_push.max():.1f} |", flush=True)


if __name__ == "__main__":
    main()
