"""How much of the reference answer no deterministic model can predict: the spread of two
Newton simulations of the same case whose starts differ by a tenth of a millimetre.

Cloth in contact is chaotic: folds and buckles that form under the same driving motion
depend on vanishingly small differences of the start. A model sees the garment, the body
and the motion, never those differences, so if two simulations started ``--jitter``
apart (Gaussian per coordinate of every unpinned vertex, seeded) end up a distance ``d``
apart, the part of the answer that depends on the start is not learnable. When the two
runs are independent draws around their conditional mean ``m`` (the perturbation has
grown to saturation), ``E|a - b|² = 2 E|a - m|²``: the best any deterministic predictor
can do is an RMS error of ``rms(a - b) / √2``. Printed per sequence and garment type,
against skinning of the draped template (the baseline of docs/results.md) and the
shipped model as ``animate`` runs it, both scored against the unperturbed run.

The sequences are the test plans of a synthetic build's config (default
``configs/data/benchmark_cmu.yaml``: unseen designs, an unseen body, the held-out
procedural motion and CMU windows of unseen subjects), one design per garment type on
the first test body. Each garment is fitted and draped as the builder does
(:func:`data_prep.drape_worker.drape_and_prepare_garment`) into ``--work``; every
finished sequence is saved there, so an interrupted run resumes.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/simulation_spread.py
        [--config configs/data/benchmark_cmu.yaml] [--work runs/simulation_spread]
        [--per-type 1] [--motions all] [--jitter 0.0001]

About three Newton simulations per sequence (~0.1–0.3 s per frame on one core: the
unperturbed run, the perturbed run and, for the first sequence, a repeat of the
unperturbed one that checks the simulator is deterministic).
"""

from __future__ import annotations

import argparse
import io
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.machine import cpu_model  # noqa: E402
from data_prep.bodies import anny_body_model, anny_shape  # noqa: E402
from data_prep.config import DataConfig  # noqa: E402
from data_prep.drape_worker import drape_and_prepare_garment  # noqa: E402
from data_prep.garment_fitting import pin_targets, read_pins  # noqa: E402
from data_prep.plan import SequencePlan, plan_dataset, planned_motion  # noqa: E402
from data_prep.simulate import (  # noqa: E402
    SimulationFailed,
    load_simulation_settings,
    simulate_garment,
)
from gnngarment.body.skinning import skin  # noqa: E402
from gnngarment.config import load_config  # noqa: E402
from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs  # noqa: E402
from gnngarment.data.cache import read_garment  # noqa: E402
from gnngarment.inference.animate import animate  # noqa: E402
from gnngarment.io.atomic import atomic_write_bytes  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402


def chosen_plans(config: DataConfig, per_type: int, motions: str) -> list[SequencePlan]:
    """Test sequences of ``config``: ``per_type`` designs of each garment type on the
    first test body, on its held-out motions (``procedural``, ``clips`` or ``all``)."""
    tests = [p for p in plan_dataset(config) if p.split == "test"]
    if not tests:
        return []
    first_body = tests[0].body.name
    designs: dict[str, list[str]] = {}
    for plan in tests:
        if plan.body.name != first_body:
            continue
        names = designs.setdefault(plan.design.garment_type, [])
        if plan.design.name not in names and len(names) < per_type:
            names.append(plan.design.name)
    keep = {name for names in designs.values() for name in names}
    return [p for p in tests if p.body.name == first_body and p.design.name in keep
            and motions in ("all", "clips" if p.motion.is_clip else "procedural")]


def mean_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Mean vertex distance [mm] (E_verts)."""
    return float(1000 * np.linalg.norm(a - b, axis=-1).mean())


def rms_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Root mean square vertex distance [mm]."""
    return float(1000 * np.sqrt((np.linalg.norm(a - b, axis=-1) ** 2).mean()))


def simulate_starts(work: Path, plan: SequencePlan, config: DataConfig,
                    starts: dict[str, np.ndarray | None]) -> dict[str, np.ndarray] | str:
    """Newton simulations of ``plan`` from each of ``starts`` (``(N, 3)`` metres; None:
    the draped template in ``work``, as the builder starts), with the body's joint
    transforms under ``"joint_transforms"`` and each run's substeps; or why the simulator
    left one out."""
    body_model = anny_body_model()
    shape = anny_shape(plan.body)
    motion = planned_motion(plan.motion, config, body_model, shape)
    with torch.no_grad():
        posed = body_model.pose(motion, shape)
    transforms = posed.joint_transforms.numpy()
    garment = read_garment(work, plan.garment)
    pinned, joint = read_pins(work, plan.garment)
    targets = pin_targets(garment.rest_pos, pinned, joint, transforms) if len(pinned) else None
    settings = load_simulation_settings(config.simulation)
    if config.settle_frames >= 0:
        settings.settle_frames = config.settle_frames
    runs: dict[str, np.ndarray] = {"joint_transforms": transforms}
    for key, start in starts.items():
        try:
            result = simulate_garment(garment.rest_pos if start is None else start,
                                      garment.faces, posed.vertices.numpy(),
                                      body_model.faces, config.fps, fabric=plan.design.fabric,
                                      pinned=pinned if len(pinned) else None,
                                      pin_targets=targets, settings=settings)
        except SimulationFailed as error:
            return f"{key}: {error}"
        runs[key] = result.positions
        runs[f"{key}_substeps"] = np.array(result.substeps)
    return runs


def simulate_twice(work: Path, plan: SequencePlan, config: DataConfig, jitter: float,
                   repeat: bool) -> dict[str, np.ndarray] | str:
    """The unperturbed and the perturbed simulation of ``plan`` (and a repeat of the
    unperturbed one when ``repeat``), with the body's joint transforms; or why the
    simulator left it out."""
    garment = read_garment(work, plan.garment)
    pinned, _ = read_pins(work, plan.garment)
    free = np.ones(len(garment.rest_pos), bool)
    free[pinned] = False
    noise = np.random.default_rng(0).normal(0.0, jitter, garment.rest_pos.shape)
    starts: dict[str, np.ndarray | None] = {
        "answer": None, "perturbed": garment.rest_pos + noise * free[:, None]}
    if repeat:
        starts["repeat"] = None
    return simulate_starts(work, plan, config, starts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--config", type=Path,
                        default=ROOT / "configs/data/benchmark_cmu.yaml")
    parser.add_argument("--work", type=Path, default=ROOT / "runs/simulation_spread")
    parser.add_argument("--per-type", type=int, default=1,
                        help="designs of each garment type (on the first test body)")
    parser.add_argument("--motions", choices=("all", "procedural", "clips"), default="all")
    parser.add_argument("--jitter", type=float, default=1e-4,
                        help="standard deviation of the start's perturbation [m]")
    args = parser.parse_args()
    torch.set_num_threads(1)
    config = load_config(args.config, DataConfig)
    plans = chosen_plans(config, args.per_type, args.motions)
    if not plans:
        sys.exit(f"error: {args.config}: no test sequences")
    model = load_model(SHIPPED_MODEL)
    body_model = anny_body_model()
    print(f"{len(plans)} test sequences of {args.config.name}; start perturbation "
          f"{1000 * args.jitter:.2f} mm; {SHIPPED_MODEL.name}; {cpu_model()}, load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores", flush=True)
    print("| sequence | type | frames | spread mm | spread, last half | floor rms / skinning "
          "rms | skinning mm | ours mm | ours / skinning | skinning vs perturbed |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    rows: list[dict[str, float | str]] = []
    for number, plan in enumerate(plans):
        saved = args.work / "spread" / f"{plan.name}.npz"
        if not saved.is_file():
            if not (args.work / "garments" / f"{plan.garment}.npz").is_file():
                status = drape_and_prepare_garment((str(args.work), plan.design, plan.body,
                                                    config, "simulation_spread"))
                if not status.get("ok"):
                    print(f"| {plan.name} | {plan.design.garment_type} | left out: "
                          f"{status.get('reason', status)} |", flush=True)
                    continue
            started = time.perf_counter()
            runs = simulate_twice(args.work, plan, config, args.jitter, repeat=number == 0)
            if isinstance(runs, str):
                print(f"| {plan.name} | {plan.design.garment_type} | left out: {runs} |",
                      flush=True)
                continue
            runs["seconds"] = np.array(time.perf_counter() - started)
            saved.parent.mkdir(parents=True, exist_ok=True)
            buffer = io.BytesIO()
            np.savez(buffer, **runs)
            atomic_write_bytes(saved, buffer.getvalue())
        with np.load(saved) as stored:
            runs = {key: stored[key] for key in stored.files}
        if int(runs["answer_substeps"]) != int(runs["perturbed_substeps"]):
            print(f"| {plan.name} | {plan.design.garment_type} | the two runs needed different "
                  f"substeps ({runs['answer_substeps']} vs {runs['perturbed_substeps']}): "
                  "not compared |", flush=True)
            continue
        garment = read_garment(args.work, plan.garment)
        answer, perturbed = runs["answer"], runs["perturbed"]
        transforms = runs["joint_transforms"]
        skinned = skin(torch.from_numpy(garment.rest_pos), None,
                       torch.from_numpy(garment.body_weights),
                       torch.from_numpy(transforms)).numpy()
        shape = anny_shape(plan.body)
        motion = planned_motion(plan.motion, config, body_model, shape)
        body = body_shape_inputs(body_model, shape, model.config.body_vertices)
        frames = body_motion_inputs(body_model, shape, motion, model.config.body_vertices)
        ours = np.asarray(animate(model, garment.rest_pos, garment.faces, body, frames).posed)
        half = len(answer) // 2
        row: dict[str, float | str] = {
            "type": plan.design.garment_type,
            "spread": mean_distance(answer, perturbed),
            "spread_late": mean_distance(answer[half:], perturbed[half:]),
            "floor_rms": rms_distance(answer, perturbed) / math.sqrt(2),
            "skinning_rms": rms_distance(skinned, answer),
            "skinning": mean_distance(skinned, answer),
            "skinning_perturbed": mean_distance(skinned, perturbed),
            "ours": mean_distance(ours, answer),
        }
        rows.append(row)
        if "repeat" in runs:
            print(f"repeat of the unperturbed run: {mean_distance(runs['repeat'], answer):.4f} "
                  "mm from it (0: the simulator is deterministic)", flush=True)
        print(f"| {plan.name} | {row['type']} | {len(answer)} | {row['spread']:.2f} | "
              f"{row['spread_late']:.2f} | {row['floor_rms'] / row['skinning_rms']:.2f} | "
              f"{row['skinning']:.2f} | {row['ours']:.2f} | "
              f"{row['ours'] / row['skinning']:.2f} | {row['skinning_perturbed']:.2f} |",
              flush=True)
    if not rows:
        sys.exit("error: every sequence was left out")
    print("\n| garment type | sequences | spread mm | skinning mm | ours mm | floor rms / "
          "skinning rms | ours / skinning |")
    print("|---|---|---|---|---|---|---|")
    kinds = [*sorted({str(r["type"]) for r in rows}), "all"]
    for kind in kinds:
        group = [r for r in rows if kind in ("all", r["type"])]
        mean = {key: float(np.mean([r[key] for r in group]))
                for key in ("spread", "skinning", "ours", "floor_rms", "skinning_rms")}
        print(f"| {'**all**' if kind == 'all' else kind} | {len(group)} | "
              f"{mean['spread']:.2f} | {mean['skinning']:.2f} | {mean['ours']:.2f} | "
              f"{mean['floor_rms'] / mean['skinning_rms']:.2f} | "
              f"{mean['ours'] / mean['skinning']:.2f} |")


if __name__ == "__main__":
    main()
