"""Cost of collision resolution per frame, against the network's time per frame.

A ~5k-vertex flared skirt on the Anny body walking, the shipped model
(``models/gnngarment-small.pt``, ``configs/model/small.yaml``), prints, measured in one
run for each of two skirts — ``loose`` (waist radius 0.17 m, hem 0.30 m: few contacts)
and ``tight`` (0.15 m / 0.20 m: the legs go through it, a stress case):

* the network's time per frame at batch 16 (``animate``'s chunk loop, resolution off);
* :func:`~gnngarment.geometry.body_collisions.resolve_collisions` per frame on the
  network's output against the posed body (one Warp mesh per animation, refit per frame)
  and what it did (vertices inside / closer than ε per frame, moved, largest push);
* the rest garment's resolution against the rest body (once per animation);
* the ratio resolution ÷ network per frame (the goal: ≤ 0.2).

    .venv/bin/python benchmarks/collision_resolution_speed.py [--vertices 5000]
        [--frames 48] [--repeats 3] [--threads 1]

Timings are the best of ``--repeats`` runs after a warm-up (Warp compiles its kernels
on first use); network and resolution runs alternate, so they share the machine's load.
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

from data_prep.garments.skirt import flared_skirt  # noqa: E402
from gnngarment.body import AnnyBodyModel, load_motion  # noqa: E402
from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs  # noqa: E402
from gnngarment.geometry.body_collisions import CollisionSettings, resolve_collisions  # noqa: E402
from gnngarment.inference.animate import animate  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402

#: name → (waist radius, hem radius) [m].
SKIRTS = {"loose": (0.17, 0.30), "tight": (0.15, 0.20)}
BATCH = 16


def shipped_model_walking(frames: int, fps: float = 30.0):
    """The shipped model, Anny's 'average' body and its inputs walking for ``frames``
    frames at ``fps``: the scene of this benchmark and of layer_resolution_speed.py.

    Returns:
        ``(model, body, frames)``: the deformer, body-shape inputs, body-motion inputs.
    """
    model = load_model(SHIPPED_MODEL)
    body_model = AnnyBodyModel()
    shape = body_model.parse_shape("average")
    body = body_shape_inputs(body_model, shape, model.config.body_vertices)
    motion = load_motion("walk", fps=fps, duration=frames / fps)
    return model, body, body_motion_inputs(body_model, shape, motion,
                                           model.config.body_vertices)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--vertices", type=int, default=5000)
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=1, help="torch intra-op threads")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    settings = CollisionSettings()
    model, body, frames = shipped_model_walking(args.frames)
    count = len(frames.vertices)
    print(f"{SHIPPED_MODEL.name}, Anny 'average' walking, {count} frames, batch {BATCH}, "
          f"torch threads {args.threads} (Warp: one core), best of {args.repeats}; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; "
          f"ε = {1000 * settings.epsilon:.1f} mm, body {len(body.faces)} triangles")
    print("| skirt | vertices | rest: moved out (ms) | inside / <ε per frame | moved per frame "
          "| largest push mm | network ms/frame | resolution ms/frame | ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    pelvis = body.joints[0]
    for name, (waist, hem) in SKIRTS.items():
        pos, faces = flared_skirt(args.vertices, waist_radius=waist, hem_radius=hem,
                                  length=0.4, waist_height=float(pelvis[2]) + 0.08, seed=1)
        pos[:, :2] += pelvis[:2]
        tic = time.perf_counter()
        rest, rest_stats = resolve_collisions(pos, faces, body.rest_vertices, body.faces,
                                              settings)
        rest_seconds = time.perf_counter() - tic
        network, resolution = [], []
        for repeat in range(args.repeats + 1):  # the first round warms up
            animation = animate(model, rest, faces, body, frames, chunk=BATCH,
                                resolve_collisions=False)
            tic = time.perf_counter()
            _, stats = resolve_collisions(animation.raw_posed, faces, frames.vertices,
                                          body.faces, settings)
            if repeat:
                resolution.append((time.perf_counter() - tic) / count)
                network.append(animation.seconds["frames"] / count)
        assert int(stats.remaining.sum()) == 0, "vertices left closer than ε"
        net, res = min(network), min(resolution)
        print(f"| {name} | {len(pos)} | {int(rest_stats.close[0])} ({1000 * rest_seconds:.0f}) "
              f"| {stats.inside.mean():.0f} / {stats.close.mean():.0f} "
              f"| {stats.moved.mean():.0f} | {1000 * stats.max_push.max():.1f} "
              f"| {1000 * net:.1f} | {1000 * res:.2f} | {res / net:.3f} |", flush=True)


if __name__ == "__main__":
    main()
