"""Paper Fig. 3 as a number: the influence field of a vertex in the multilevel model
(``levels=2``) against single-level models.

For every garment and target vertex, the blend shape ``‖B_v‖`` of the target is
attributed to the graph features by integrated gradients (Eq. 9, 50 Gauss–Legendre
points) and the normal-channel heat is measured (:func:`influence_field`): the
vertices, geodesic radius and hop radius holding 90% (and 99%) of the attribution mass.
Three models, same widths (``configs/model/small.yaml``):

* ``single``: ``levels=0`` — the processor is the embedding and output GATs only;
* ``cascade``: the ``levels=2`` network with the *same weights* as ``multi`` but every
  pooling step replaced by the identity (keep all vertices, same edges, identity
  unpooling): the paper's single-level baseline, whose GATs are "cascade connected",
  at equal depth. ``multi`` against ``cascade`` isolates what pooling adds;
* ``multi``: ``levels=2`` with structure-preserving pooling (Algorithms 1–2).

Untrained (seeded) models compare receptive fields, which is what the architecture
decides; pass ``--checkpoint-single``/``--checkpoint-multi`` to compare trained
models (``cascade`` is then left out: it would need its own training).

    .venv/bin/python benchmarks/influence_field.py \\
        [--checkpoint-single A.pt --checkpoint-multi B.pt] [--images docs/images/attribution]

Garments: an irregular flared skirt (``data_prep.garments.flared_skirt``) and a
regular tube (``tests.meshes.tube``), on a synthetic T-pose skeleton (or the Anny rest
body with ``--body anny``), at one frame of a seeded random motion (``--body anny``: a
walk).
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import torch

from data_prep.garments import flared_skirt
from gnngarment.attribution import (
    FrameInputs,
    attribute,
    hop_distances,
    influence_field,
    mass_profile,
    render_comparison,
)
from gnngarment.body.joint_reach import joint_region_distances
from gnngarment.body.weight_transfer import transfer_body_weights
from gnngarment.config import load_config
from gnngarment.data.pair import GarmentBodyPair
from gnngarment.geometry.hierarchy import PoolHierarchy, PoolLevel
from gnngarment.geometry.prepare import GarmentPreparationConfig, prepare_garment
from gnngarment.model.checkpoint import load_model
from gnngarment.model.config import ModelConfig
from gnngarment.model.deformer import GarmentDeformer
from gnngarment.paths import default_config

#: A T-pose skeleton (metres, Z up, facing −Y, pelvis at the origin) for the
#: synthetic body: only the joint-distance features need it.
T_POSE_JOINTS = np.array([
    [0.0, 0.0, 0.0], [0.09, 0.0, -0.08], [-0.09, 0.0, -0.08], [0.0, 0.0, 0.11],
    [0.1, 0.0, -0.5], [-0.1, 0.0, -0.5], [0.0, 0.0, 0.24], [0.1, 0.02, -0.9],
    [-0.1, 0.02, -0.9], [0.0, 0.0, 0.3], [0.1, -0.1, -0.96], [-0.1, -0.1, -0.96],
    [0.0, 0.0, 0.5], [0.08, 0.0, 0.43], [-0.08, 0.0, 0.43], [0.0, -0.02, 0.6],
    [0.18, 0.0, 0.42], [-0.18, 0.0, 0.42], [0.45, 0.0, 0.42], [-0.45, 0.0, 0.42],
    [0.7, 0.0, 0.42], [-0.7, 0.0, 0.42], [0.78, 0.0, 0.42], [-0.78, 0.0, 0.42],
])
MODELS = ("single", "cascade", "multi")


@dataclass
class Body:
    joints: np.ndarray        # (24, 3)
    distances: np.ndarray     # (N_b', 24)
    frame: FrameInputs
    rest_vertices: np.ndarray | None = None     # (N_b, 3), a real body only
    skinning_weights: np.ndarray | None = None  # (N_b, 24), a real body only

    def garment_weights(self, pos: np.ndarray) -> np.ndarray:
        """``(N, 24)`` body skinning weights of the garment (the ``body`` weight prior):
        transferred from a real body; on the synthetic skeleton, a soft nearest-joint
        assignment (5 cm temperature)."""
        if self.rest_vertices is not None and self.skinning_weights is not None:
            return transfer_body_weights(pos, self.rest_vertices, self.skinning_weights)
        distance = np.linalg.norm(pos[:, None] - self.joints[None], axis=-1)
        logits = -(distance - distance.min(axis=1, keepdims=True)) / 0.05
        weights = np.exp(logits)
        return (weights / weights.sum(axis=1, keepdims=True)).astype(np.float32)

    def joint_distances(self, pos: np.ndarray) -> np.ndarray:
        """``(N, 24)`` how far each joint's body region lies beyond the body (the weight
        reach): measured on a real body; on the synthetic skeleton, each joint's
        distance beyond the nearest joint."""
        if self.rest_vertices is not None and self.skinning_weights is not None:
            return joint_region_distances(pos, self.rest_vertices, self.skinning_weights)
        distance = np.linalg.norm(pos[:, None] - self.joints[None], axis=-1)
        return distance - distance.min(axis=1, keepdims=True)


def garments(skirt_vertices: int, tube_shape: tuple[int, int], waist: np.ndarray
             ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The procedural garments, hung at ``waist`` (the pelvis + 8 cm)."""
    import sys

    # tests/ is not installed: reach tests.meshes from the repository root.
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from tests.meshes import tube

    skirt = flared_skirt(skirt_vertices, seed=0)
    rings, sections = tube_shape
    tube_pos, tube_faces = tube(rings, sections, radius=0.2, height=0.6)
    tube_pos = tube_pos - np.array([0.0, 0.0, 0.6])          # top ring at z = 0
    return {f"skirt{len(skirt[0])}": (skirt[0] + waist, skirt[1]),
            f"tube{len(tube_pos)}": (tube_pos + waist, tube_faces)}


def target_vertices(pos: np.ndarray, count: int) -> list[int]:
    """``count`` front (−Y) vertices at evenly spaced heights between 20% and 80% of
    the garment's height: near the waist, the middle, near the hem."""
    low, high = pos[:, 2].min(), pos[:, 2].max()
    span = high - low
    front = np.array([0.0, -1.0])
    centre = pos[:, :2].mean(axis=0)
    targets = []
    for fraction in np.linspace(0.8, 0.2, count):
        height = low + fraction * span
        radial = pos[:, :2] - centre
        facing = radial @ front / np.maximum(np.linalg.norm(radial, axis=1), 1e-9)
        score = np.abs(pos[:, 2] - height) / span + (1.0 - facing)
        targets.append(int(np.argmin(score)))
    return targets


def unpooled(hierarchy: PoolHierarchy, levels: int) -> PoolHierarchy:
    """The hierarchy of the ``cascade`` model: ``levels`` identity pooling steps."""
    n = hierarchy.num_vertices
    identity = PoolLevel(kept=np.arange(n, dtype=np.int64), edge_index=hierarchy.edge_index,
                         unpool=sp.identity(n, format="csr", dtype=np.float64),
                         centres=np.zeros(1, dtype=np.int64))
    return PoolHierarchy(num_vertices=n, edge_index=hierarchy.edge_index,
                         levels=[identity] * levels)


def synthetic_body(config: ModelConfig, seed: int) -> Body:
    """The T-pose skeleton, a random body-shape feature and a random frame (seeded)."""
    generator = torch.Generator().manual_seed(seed)
    rng = np.random.default_rng(seed)
    window = config.window
    transforms = torch.eye(4).repeat(1, 1, 24, 1, 1)
    transforms[..., :3, 3] = torch.randn(1, 1, 24, 3, generator=generator) * 0.02
    frame = FrameInputs(
        motion_window=torch.randn(1, 1, window, 75, generator=generator) * 0.2,
        velocity_window=torch.randn(1, 1, window, 3 * config.body_vertices,
                                    generator=generator) * 0.1,
        joint_transforms=transforms)
    distances = rng.random((config.body_vertices, 24)).astype(np.float32)
    return Body(joints=T_POSE_JOINTS.copy(), distances=distances, frame=frame)


def anny_body(config: ModelConfig, frame_index: int) -> Body:
    """Anny's default shape in its rest pose, frame ``frame_index`` of a walk."""
    from gnngarment.body.factory import create_body_model
    from gnngarment.body.motion_io import load_motion
    from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs

    body_model = create_body_model()
    shape = body_model.default_shape()
    rest = body_shape_inputs(body_model, shape, config.body_vertices)
    motion = load_motion("walk", fps=30.0, duration=2.0)
    frames = body_motion_inputs(body_model, shape, motion, config.body_vertices)
    return Body(joints=rest.joints, distances=rest.distances,
                frame=FrameInputs.from_motion(frames, frame_index, config.window),
                rest_vertices=rest.rest_vertices, skinning_weights=rest.skinning_weights)


def make_pair(pos: np.ndarray, faces: np.ndarray, body: Body, config: ModelConfig,
              hierarchy_levels: int) -> GarmentBodyPair:
    from gnngarment.data.vertex_features import garment_vertex_features

    prepared = prepare_garment(pos, faces, GarmentPreparationConfig(
        levels=hierarchy_levels, landmarks=config.landmarks))
    return GarmentBodyPair.from_arrays(
        pos, garment_vertex_features(pos, faces, body.joints), prepared.hierarchy,
        prepared.descriptor, body.distances, body.garment_weights(pos),
        body.joint_distances(pos))


def build_models(arguments: argparse.Namespace) -> dict[str, GarmentDeformer]:
    if arguments.checkpoint_single or arguments.checkpoint_multi:
        if not (arguments.checkpoint_single and arguments.checkpoint_multi):
            raise SystemExit("give both --checkpoint-single and --checkpoint-multi")
        models = {"single": load_model(arguments.checkpoint_single),
                  "multi": load_model(arguments.checkpoint_multi)}
        for name, model in models.items():
            print(f"{name}: {arguments.__dict__['checkpoint_' + name]} "
                  f"(levels={model.config.levels}, pooling={model.config.pooling})")
        return models
    base = load_config(arguments.config, ModelConfig)
    models = {}
    for name, levels in (("single", 0), ("multi", 2)):
        torch.manual_seed(arguments.seed)
        models[name] = GarmentDeformer(replace(base, levels=levels)).eval()
    models["cascade"] = models["multi"]        # same weights, identity pooling
    return {name: models[name] for name in MODELS}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", type=Path, default=default_config("model/small.yaml"),
                        help="model widths of the untrained models")
    parser.add_argument("--checkpoint-single", type=Path, help="trained levels=0 model")
    parser.add_argument("--checkpoint-multi", type=Path, help="trained levels=2 model")
    parser.add_argument("--body", choices=("synthetic", "anny"), default="synthetic")
    parser.add_argument("--skirt-vertices", type=int, default=2000)
    parser.add_argument("--tube", type=int, nargs=2, default=(30, 40), metavar=("RINGS",
                        "SECTIONS"))
    parser.add_argument("--targets", type=int, default=3, help="target vertices per garment")
    parser.add_argument("--n-steps", type=int, default=50)
    parser.add_argument("--mass", type=float, default=0.9)
    parser.add_argument("--heat", choices=("normal", "all"), default="normal")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, help="torch CPU threads (default: torch's)")
    parser.add_argument("--images", type=Path, help="write comparison PNGs here")
    parser.add_argument("--json", type=Path, help="write every number here")
    arguments = parser.parse_args()
    if arguments.threads:
        torch.set_num_threads(arguments.threads)

    models = build_models(arguments)
    config = models["multi"].config
    body = (anny_body(config, 20) if arguments.body == "anny"
            else synthetic_body(config, arguments.seed))
    waist = body.joints[0] + np.array([0.0, 0.0, 0.08])
    depth = max(model.config.levels for model in models.values())
    rows, profiles = [], {}
    print(f"{'garment':10} {'target':>6} {'model':8} {'count90':>8} {'radius90 m':>10} "
          f"{'hops90':>6} {'count99':>8} {'hops99':>6} {'support':>8} {'supp.hops':>9} "
          f"{'rel.delta':>9} {'s':>6}", flush=True)
    for garment, (pos, faces) in garments(arguments.skirt_vertices, arguments.tube,
                                          waist).items():
        pair = make_pair(pos, faces, body, config, hierarchy_levels=max(depth, 2))
        pairs = {"single": pair, "multi": pair,
                 "cascade": replace(pair, hierarchy=unpooled(pair.hierarchy, 2))}
        edge_index = pair.hierarchy.edge_index
        targets = target_vertices(pos, arguments.targets)
        for target in targets:
            hops = hop_distances(edge_index, len(pos), np.array([target]))
            heats = {}
            for name, model in models.items():
                result = attribute(model, pairs[name], body.frame, target="vertex",
                                   target_vertices=target, n_steps=arguments.n_steps)
                heat = result.heat(arguments.heat)
                heats[name] = heat
                field = influence_field(heat, pos, edge_index, target, arguments.mass)
                tail = influence_field(heat, pos, edge_index, target, 0.99)
                row = {"garment": garment, "vertices": len(pos), "target": target,
                       "model": name, "count90": field.count, "radius90": field.radius,
                       "hops90": field.hops, "count99": tail.count, "radius99": tail.radius,
                       "hops99": tail.hops, "support": field.support,
                       "support_hops": field.support_hops, "value": result.value,
                       "delta": result.delta, "relative_delta": result.relative_delta,
                       "seconds": result.seconds}
                rows.append(row)
                print(f"{garment:10} {target:6d} {name:8} {field.count:8d} "
                      f"{field.radius:10.3f} {field.hops:6d} {tail.count:8d} {tail.hops:6d} "
                      f"{field.support:8d} {field.support_hops:9d} "
                      f"{result.relative_delta:9.1e} {result.seconds:6.1f}", flush=True)
                profiles[(garment, target, name)] = mass_profile(heat, hops, np.arange(61))
            if arguments.images is not None and target == targets[len(targets) // 2]:
                path = arguments.images / f"{garment}_v{target}.png"
                render_comparison(path, pos, faces, [heats[m] for m in models],
                                  [_title(m, models[m]) for m in models], targets=[target],
                                  scale="log", suptitle=f"{garment}: attribution of "
                                  f"‖B‖ at vertex {target} (normal channels, log scale)")
                print(f"  wrote {path}", flush=True)

    print_ratios(rows, list(models))
    if arguments.images is not None:
        path = arguments.images / "mass_profile.png"
        plot_profiles(path, profiles, list(models))
        print(f"wrote {path}")
    if arguments.json is not None:
        arguments.json.write_text(json.dumps({"rows": rows, "arguments": {
            k: str(v) for k, v in vars(arguments).items()}}, indent=2))
        print(f"wrote {arguments.json}")


def _title(name: str, model: GarmentDeformer) -> str:
    return {"single": "single-level (levels=0)",
            "cascade": "depth-matched, no pooling",
            "multi": f"multilevel (levels={model.config.levels})"}[name]


def print_ratios(rows: list[dict], names: list[str]) -> None:
    """Geometric means over garments and targets of the field ratios to ``multi``."""
    print("\nratio multi / baseline (geometric mean over garments × targets; > 1: the "
          "multilevel field is wider)")
    keys = ("count90", "radius90", "hops90", "count99", "radius99", "hops99", "support",
            "support_hops")
    print(f"{'baseline':10}" + "".join(f"{k:>13}" for k in keys))
    by = {(r["garment"], r["target"], r["model"]): r for r in rows}
    cases = sorted({(r["garment"], r["target"]) for r in rows})
    for baseline in (n for n in names if n != "multi"):
        ratios = []
        for key in keys:
            values = [by[(*case, "multi")][key] / max(by[(*case, baseline)][key], 1e-12)
                      for case in cases]
            ratios.append(float(np.exp(np.mean(np.log(np.maximum(values, 1e-12))))))
        print(f"{baseline:10}" + "".join(f"{v:13.2f}" for v in ratios))
    seconds = [r["seconds"] for r in rows]
    deltas = [r["relative_delta"] for r in rows]
    print(f"\nattribution: {np.mean(seconds):.1f} s mean per run; relative completeness "
          f"delta max {max(deltas):.1e}")


def plot_profiles(path: Path, profiles: dict, names: list[str]) -> None:
    """Fraction of the attribution mass *beyond* ``h`` hops of the target (log scale,
    so the tail the pooled levels carry is visible), one line per target and model."""
    import io

    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    from gnngarment.io.atomic import atomic_write_bytes

    garments_seen = sorted({key[0] for key in profiles})
    figure = Figure(figsize=(4.6 * len(garments_seen), 3.6))
    colors = {"single": "#1f77b4", "cascade": "#2ca02c", "multi": "#d62728"}
    for k, garment in enumerate(garments_seen):
        axes = figure.add_subplot(1, len(garments_seen), k + 1)
        last = 1
        for (g, _, name), profile in profiles.items():
            if g == garment:
                outside = np.maximum(1.0 - profile, 0.0)
                hops = np.arange(len(profile))
                shown = outside > 1e-9
                last = max(last, int(hops[shown].max(initial=0)) + 2)
                axes.semilogy(hops[shown], outside[shown], color=colors.get(name, "k"),
                              alpha=0.8, label=name, marker=".", ms=3)
        handles, labels = axes.get_legend_handles_labels()
        unique = dict(zip(labels, handles, strict=True))
        axes.legend(unique.values(), unique.keys(), loc="upper right", fontsize=8)
        axes.axhline(0.1, color="grey", lw=0.6, ls="--")
        axes.set_xlim(0, last)
        axes.xaxis.set_major_locator(MaxNLocator(integer=True))
        axes.set_ylim(1e-9, 1.5)
        axes.set_xlabel("hops from the target vertex")
        axes.set_ylabel("fraction of attribution mass beyond")
        axes.set_title(garment, fontsize=9)
        axes.grid(alpha=0.3)
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=110)
    atomic_write_bytes(path, buffer.getvalue())


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"total {time.perf_counter() - started:.0f} s")
