"""Layered outfits against Newton: the outfit simulated in one scene is the answer.

For every test body of a synthetic build (default ``data/benchmark_cmu``), the test
designs draped on it are paired into outfits — a bottom (trousers, skirt) under a top
(T-shirt, top) — and, on the build's held-out procedural motion of that body:

* **Newton**: both garments in one scene with the simulator's cloth self-contact (as
  ``animate --drape`` settles an outfit), each hanging from its pins as the builder's
  single-garment sequences do, from their drapes on the rest body with the top first
  kept 1.5× the self-contact distance outside the bottom (the layer resolution at
  rest: the two were draped apart);
* **ours**: the shipped model animating the two as an outfit
  (:func:`gnngarment.inference.outfit.animate_outfit`: body resolution, then the layer
  resolution) and the top alone (body resolution only);
* **body skinning** of each garment (its transferred body weights, no learning).

It prints per outfit and overall: inter-garment penetration (% of the top's vertices
behind the bottom; :func:`gnngarment.geometry.garment_layers.layer_penetration`) of
Newton's answer, of our raw output and after resolution; each garment's E_verts (mm,
against Newton's outfit) as an outfit and, for the top, alone.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/layered_outfits.py [--data data/benchmark_cmu]
        [--config configs/data/benchmark_cmu.yaml] [--outfits 6] [--motions all]

Issue 40's bars: penetration after resolution ≤ Newton's own; each garment's E_verts as
an outfit within +2 % of resolving it alone.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from data_prep.bodies import anny_body_model, anny_shape  # noqa: E402
from data_prep.config import DataConfig  # noqa: E402
from data_prep.garment_fitting import pin_targets, read_pins  # noqa: E402
from data_prep.plan import plan_dataset, planned_motion  # noqa: E402
from data_prep.simulate import (  # noqa: E402
    SimulationFailed,
    load_simulation_settings,
    simulate_garment,
)
from gnngarment.body.skinning import skin  # noqa: E402
from gnngarment.config import load_config  # noqa: E402
from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs  # noqa: E402
from gnngarment.data.cache import read_garment  # noqa: E402
from gnngarment.geometry.garment_layers import (  # noqa: E402
    LayerSettings,
    layer_penetration,
    outward_faces,
    resolve_layer_collisions,
)
from gnngarment.inference.animate import animate  # noqa: E402
from gnngarment.inference.outfit import OutfitGarment, animate_outfit  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402

BOTTOMS = ("trousers", "skirt")
TOPS = ("tshirt", "top")


def outfits(config: DataConfig, root: Path, count: int, motions: str
            ) -> list[tuple[object, object, object]]:
    """``(bottom plan, top plan, sequence plan)`` per outfit and motion: test designs
    draped on the same test body (a design whose drape the build left out is skipped),
    bottoms and tops paired in turn, on the held-out motions of the bottom's test
    sequences (``motions``: ``procedural``, ``clips`` — its CMU windows — or ``all``)."""
    tests = [p for p in plan_dataset(config) if p.split == "test"
             and (root / "garments" / f"{p.garment}.npz").is_file()]
    plans = [p for p in tests if not p.motion.is_clip]
    by_body: dict[str, dict[str, list]] = {}
    for plan in plans:
        kinds = by_body.setdefault(plan.body.name, {"bottom": [], "top": []})
        kind = ("bottom" if plan.design.garment_type in BOTTOMS
                else "top" if plan.design.garment_type in TOPS else None)
        if kind and plan not in kinds[kind]:
            kinds[kind].append(plan)
    chosen = []
    for kinds in by_body.values():
        for bottom, top in zip(kinds["bottom"], kinds["top"], strict=False):
            chosen.append((bottom, top))
    return [(bottom, top, plan) for bottom, top in chosen[:count] for plan in tests
            if plan.garment == bottom.garment
            and motions in ("all", "clips" if plan.motion.is_clip else "procedural")]


def cpu_model() -> str:
    """The CPU's model name, as ``lscpu`` prints it."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def pinned_scene(root: Path, names: list[str], transforms: np.ndarray, offsets: list[int]):
    """The pins of every garment of the scene (indices into the concatenated mesh) and
    their targets per frame, each following its own joint rigidly."""
    pins, targets = [], []
    for name, offset in zip(names, offsets, strict=True):
        pinned, joint = read_pins(root, name)
        if not len(pinned):
            continue
        targets.append(pin_targets(read_garment(root, name).rest_pos, pinned, joint,
                                   transforms))
        pins.append(pinned + offset)
    if not pins:
        return None, None
    return np.concatenate(pins), np.concatenate(targets, axis=1)


def e_verts(pred: np.ndarray, answer: np.ndarray) -> float:
    return float(1000 * np.linalg.norm(pred - answer, axis=-1).mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT / "data/benchmark_cmu")
    parser.add_argument("--config", type=Path, default=ROOT / "configs/data/benchmark_cmu.yaml")
    parser.add_argument("--outfits", type=int, default=6)
    parser.add_argument("--motions", choices=("all", "procedural", "clips"), default="all",
                        help="the held-out procedural motion, the CMU windows, or both")
    args = parser.parse_args()
    torch.set_num_threads(1)
    config = load_config(args.config, DataConfig)
    chosen = outfits(config, args.data, args.outfits, args.motions)
    if not chosen:
        sys.exit(f"error: {args.config}: no test body has both a bottom and a top design")
    model = load_model(SHIPPED_MODEL)
    body_model = anny_body_model()
    layers = LayerSettings()
    settings = load_simulation_settings(config.simulation)
    settings.self_contact = True
    if config.settle_frames >= 0:
        settings.settle_frames = config.settle_frames
    print(f"{SHIPPED_MODEL.name}; {len(chosen)} outfit sequences of {args.data}; clearance "
          f"{1000 * layers.clearance:.0f} mm; {cpu_model()}, "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print("| outfit | motion | frames | Newton s | through: Newton | ours raw | ours resolved "
          "| bottom E_verts: ours / body skinning | top E_verts: outfit / alone / body skinning |")
    print("|---|---|---|---|---|---|---|---|---|")
    totals: dict[str, list[float]] = {}
    for bottom_plan, top_plan, plan in chosen:
        shape = anny_shape(plan.body)
        motion = planned_motion(plan.motion, config, body_model, shape)
        with torch.no_grad():
            posed = body_model.pose(motion, shape)
        body_vertices = posed.vertices.numpy()
        transforms = posed.joint_transforms.numpy()
        body = body_shape_inputs(body_model, shape, model.config.body_vertices)
        bottom, top = (read_garment(args.data, p.garment) for p in (bottom_plan, top_plan))
        # The two were draped apart: the top is first moved out of the bottom, farther
        # than the simulator's self-contact distance (a start inside it is an impulse
        # that fails the stretch gate within a few frames: measured, 2026-12-07).
        bottom_out = outward_faces(bottom.rest_pos, bottom.faces, body.rest_vertices, body.faces)
        start = replace(layers, clearance=max(layers.clearance,
                                              1.5 * settings.self_contact_distance))
        top_rest, _ = resolve_layer_collisions(top.rest_pos, top.faces,
                                               [(bottom.rest_pos, bottom_out)], start)
        scene = np.concatenate([bottom.rest_pos, top_rest])
        faces = np.concatenate([bottom.faces, top.faces + len(bottom.rest_pos)])
        pinned, pin_targets = pinned_scene(args.data, [bottom_plan.garment, top_plan.garment],
                                           transforms, [0, len(bottom.rest_pos)])
        started = time.perf_counter()
        try:
            result = simulate_garment(scene, faces, body_vertices, body_model.faces, config.fps,
                                      fabric=top_plan.design.fabric, pinned=pinned,
                                      pin_targets=pin_targets, settings=settings)
        except SimulationFailed as error:  # as the builder does: left out, said so
            print(f"| {bottom_plan.design.name} + {top_plan.garment} | {plan.motion.name} | "
                  f"left out: {error} |", flush=True)
            continue
        newton_seconds = time.perf_counter() - started
        answer_bottom = result.positions[:, :len(bottom.rest_pos)]
        answer_top = result.positions[:, len(bottom.rest_pos):]
        frames = body_motion_inputs(body_model, shape, motion, model.config.body_vertices)
        outfit = animate_outfit(model, [OutfitGarment(bottom_plan.garment, bottom.rest_pos,
                                                      bottom.faces),
                                        OutfitGarment(top_plan.garment, top_rest, top.faces)],
                                body, frames, layers=[bottom_plan.garment, top_plan.garment],
                                layer_settings=layers)
        alone = animate(model, top_rest, top.faces, body, frames)
        ours_bottom, ours_top = (np.asarray(a.posed) for a in outfit.animations)
        skinned = [skin(torch.from_numpy(g.rest_pos if g is bottom else top_rest), None,
                        torch.from_numpy(g.body_weights), torch.from_numpy(transforms)).numpy()
                   for g in (bottom, top)]
        row = {
            "newton": 100 * layer_penetration(answer_top, answer_bottom, bottom_out,
                                              layers).mean(),
            "raw": 100 * outfit.penetration_raw[1].mean(),
            "resolved": 100 * outfit.penetration[1].mean(),
            "bottom": e_verts(ours_bottom, answer_bottom),
            "bottom_skinning": e_verts(skinned[0], answer_bottom),
            "top_outfit": e_verts(ours_top, answer_top),
            "top_alone": e_verts(np.asarray(alone.posed), answer_top),
            "top_skinning": e_verts(skinned[1], answer_top),
        }
        for key, value in row.items():
            totals.setdefault(key, []).append(value)
        outfit_name = f"{bottom_plan.design.name} + {top_plan.garment}"
        print(f"| {outfit_name} | {plan.motion.name} | {len(motion)} | {newton_seconds:.0f} | "
              f"{row['newton']:.2f} % | {row['raw']:.2f} % | "
              f"{row['resolved']:.2f} % | {row['bottom']:.1f} / {row['bottom_skinning']:.1f} | "
              f"{row['top_outfit']:.1f} / {row['top_alone']:.1f} / {row['top_skinning']:.1f} |",
              flush=True)
    if not totals:
        sys.exit("error: Newton left out every outfit sequence (the stretch gate)")
    mean = {key: float(np.mean(values)) for key, values in totals.items()}
    simulated = len(totals["newton"])
    print(f"| **mean of {simulated} of {len(chosen)}** | | | | {mean['newton']:.2f} % | "
          f"{mean['raw']:.2f} % | "
          f"{mean['resolved']:.2f} % | {mean['bottom']:.1f} / {mean['bottom_skinning']:.1f} | "
          f"{mean['top_outfit']:.1f} / {mean['top_alone']:.1f} / {mean['top_skinning']:.1f} |")
    print(f"penetration after resolution ≤ Newton's: "
          f"{'yes' if mean['resolved'] <= mean['newton'] else 'no'}; top as an outfit vs "
          f"alone: {100 * (mean['top_outfit'] / mean['top_alone'] - 1):+.1f} % (bar ≤ +2 %)")


if __name__ == "__main__":
    main()
