"""``make demo``: the main job end to end on the embedded default.

1. build the demo dataset: procedural garments on Anny bodies, motions from the
   procedural library, ground truth simulated with NVIDIA Newton (``configs/data/demo.yaml``);
2. train the small model briefly through both stages (``configs/train/demo.yaml``);
3. evaluate it — and the shipped checkpoint — on held-out garments, bodies and motions;
4. animate an unseen garment (a new design on a body shape not in the dataset) with the
   shipped model and export OBJ/PC2/glb/GIF;
5. write an integrated-gradients attribution heatmap of that garment.

Everything lands in one folder (default ``demo_output/``) with ``summary.json``. Every
stage resumes: the dataset build skips finished sequences, training resumes from its
last checkpoint.

    python -m gnngarment.demo --out demo_output [--quick]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

from gnngarment.allocator import keep_freed_memory
from gnngarment.paths import REPOSITORY_ROOT, SHIPPED_MODEL

console = Console()

#: The unseen dress of stage 4: its (lowest, highest) vertex count and drape frame cap.
UNSEEN_RESOLUTION = (1200, 1600)
UNSEEN_DRAPE_FRAMES = 90


def unseen_garment(out: Path, seed: int = 20261123,
                   resolution: tuple[int, int] = UNSEEN_RESOLUTION,
                   drape_frames: int = UNSEEN_DRAPE_FRAMES) -> tuple[Path, Any, Any]:
    """A garment design that is in no dataset (its own seed), on a body shape that is in
    no split (the "tall" phenotype below), draped for at most ``drape_frames`` and
    written as OBJ; ``resolution`` is its (lowest, highest) vertex count. Returns the
    path, the body model and the shape."""
    import trimesh

    from data_prep.garments import BodyFrame, sample_garment
    from data_prep.simulate import drape_garment
    from gnngarment.body import AnnyBodyModel, AnnyShape

    body_model = AnnyBodyModel()
    shape = AnnyShape(gender=0.8, age=0.6, muscle=0.4, weight=0.35, height=0.7,
                      proportions=0.5)
    rest = body_model.rest(shape)
    frame = BodyFrame(vertices=rest.vertices.numpy(), faces=rest.faces,
                      joints=rest.joints.numpy())
    garment = sample_garment(frame, seed, garment_type="dress", resolution=resolution)
    # The model animates a garment as worn at rest (DESIGN.md): settle the design on the
    # rest body first, as the dataset builder does, with the reference simulator.
    draped = drape_garment(garment.pos, garment.faces, rest.vertices.numpy(), body_model.faces,
                           max_frames=drape_frames)
    console.print(f"unseen dress draped on the rest body in {draped.frames} frames "
                  f"({draped.seconds:.0f} s; it settled {1000 * draped.mean_displacement:.0f} "
                  "mm from its design on average)")
    path = out / "unseen_dress.obj"
    trimesh.Trimesh(draped.positions, garment.faces, process=False).export(path)
    return path, body_model, shape


def run(out: Path, data_config: Path, train_config: Path, model_path: Path | None,
        attribution_steps: int = 50, motion_seconds: float = 2.0,
        workspace: Path | None = None,
        unseen_resolution: tuple[int, int] = UNSEEN_RESOLUTION,
        unseen_drape_frames: int = UNSEEN_DRAPE_FRAMES) -> dict[str, Any]:
    """The five stages; ``workspace`` (if given) replaces the configs' dataset and run
    folders (``<workspace>/data``, ``<workspace>/run``); ``unseen_resolution`` and
    ``unseen_drape_frames`` size the unseen dress of stage 4 (smaller in the tests)."""
    from data_prep.build import build_dataset
    from data_prep.config import DataConfig
    from data_prep.posed_bodies import synthetic_body_meshes, synthetic_skinning_weights
    from gnngarment.attribution.heatmap_files import run_attribution
    from gnngarment.body import make_motion
    from gnngarment.config import load_config
    from gnngarment.data import PreparedDataset
    from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
    from gnngarment.evaluation import evaluate, write_report
    from gnngarment.geometry import load_mesh
    from gnngarment.inference.animate import animate
    from gnngarment.inference.export import export_animation
    from gnngarment.model.checkpoint import load_model
    from gnngarment.training.loading import load_training_config
    from gnngarment.training.trainer import Trainer

    out.mkdir(parents=True, exist_ok=True)
    seconds: dict[str, float] = {}
    summary: dict[str, Any] = {"files": {}}

    started = time.perf_counter()
    console.rule("1/5 dataset (Newton simulation)")
    data = load_config(data_config, DataConfig)
    if workspace is not None:
        data.output = str(workspace / "data")
    build = build_dataset(data, log=console.print)
    seconds["dataset"] = time.perf_counter() - started
    summary["dataset"] = {"folder": data.output, "splits": build["splits"],
                          "left_out": len(build["failed_sequences"]),
                          "seconds_per_frame": build["seconds_per_frame"]}

    started = time.perf_counter()
    console.rule("2/5 training (both stages)")
    overrides = [f"data={data.output}"]
    if workspace is not None:
        overrides.append(f"output={workspace / 'run'}")
    settings = load_training_config(train_config, overrides)
    window = settings.model.window
    validation = PreparedDataset(data.output, "val", window)
    trainer = Trainer(settings, PreparedDataset(data.output, "train", window),
                      validation if len(validation) else None)
    training = trainer.fit(resume=True)
    seconds["training"] = time.perf_counter() - started
    summary["training"] = {"epochs": training["epochs"], "switches": training["switches"],
                           "checkpoint": str(trainer.checkpoint_path())}

    started = time.perf_counter()
    console.rule("3/5 evaluation on held-out garments, bodies and motions")
    models = {"demo run": load_model(trainer.checkpoint_path())}
    model_path = model_path or (SHIPPED_MODEL if SHIPPED_MODEL.is_file() else None)
    if model_path is not None:
        shipped = load_model(model_path)
        if shipped.config.body_vertices == settings.model.body_vertices:
            models["shipped"] = shipped
    report = evaluate(models, PreparedDataset(data.output, "test", window),
                      body_meshes=synthetic_body_meshes(data.output),
                      body_skinning_weights=synthetic_skinning_weights(data.output))
    write_report(report, out / "evaluation.md", out / "evaluation.json")
    console.print(report.to_markdown())
    seconds["evaluation"] = time.perf_counter() - started
    summary["evaluation"] = {method: values["all"] for method, values in report.results.items()}
    summary["files"]["evaluation"] = str(out / "evaluation.md")

    started = time.perf_counter()
    console.rule("4/5 animate an unseen garment")
    animator = models.get("shipped", models["demo run"])
    summary["animated_with"] = "shipped" if "shipped" in models else "demo run"
    garment_path, body_model, shape = unseen_garment(out, resolution=unseen_resolution,
                                                      drape_frames=unseen_drape_frames)
    pos, faces = load_mesh(garment_path)
    body = body_shape_inputs(body_model, shape, animator.config.body_vertices)
    frames = body_motion_inputs(body_model, shape,
                                make_motion("walk", duration=motion_seconds, seed=7),
                                animator.config.body_vertices)
    animation = animate(animator, pos, faces, body, frames, source=str(garment_path))
    paths = export_animation(animation, out / "animation", garment_path.stem)
    seconds["animation"] = time.perf_counter() - started
    summary["animation"] = {"frames": int(animation.posed.shape[0]), "vertices": len(pos),
                            "model_fps": animation.posed.shape[0] / animation.seconds["frames"]}
    summary["files"] |= {key: str(path) for key, path in paths.items()}
    summary["files"]["garment"] = str(garment_path)

    started = time.perf_counter()
    console.rule("5/5 attribution heatmap (integrated gradients, Gauss-Legendre)")
    # Log colour scale: a trained model's attribution decays over decades from its target.
    attribution = run_attribution(animator, pos, faces, body, frames, out / "attribution",
                                  n_steps=attribution_steps, source=str(garment_path),
                                  scale="log")
    seconds["attribution"] = time.perf_counter() - started
    summary["attribution"] = {k: v for k, v in attribution.items()
                              if isinstance(v, (int, float, str))}
    summary["files"]["heatmap"] = str(out / "attribution" / "attribution.png")
    summary["seconds"] = seconds
    (out / "summary.json").write_text(json.dumps(summary, indent=2, default=str))
    return summary


def _print_summary(summary: dict[str, Any], out: Path, total: float) -> None:
    table = Table(title="held-out test split (mean over frames)")
    for column in ("method", "E_verts mm", "E_norm °", "collision %", "Hausdorff mm",
                   "spurious mm"):
        table.add_column(column)
    for method, values in summary["evaluation"].items():
        table.add_row(method, *(f"{values[k]:.1f}" for k in (
            "e_verts_mm", "e_norm_deg", "collision_pct", "hausdorff_mm", "spurious_mm")))
    console.print(table)
    console.print(f"animated {summary['animation']['frames']} frames of an unseen "
                  f"{summary['animation']['vertices']}-vertex dress with the "
                  f"{summary['animated_with']} model "
                  f"({summary['animation']['model_fps']:.1f} frames/s)")
    console.print("seconds: " + ", ".join(f"{k} {v:.0f}" for k, v in summary["seconds"].items())
                  + f"; total {total:.0f}")
    console.print(f"[bold]outputs in {out}/[/]:")
    for key in ("garment", "glb", "pc2", "obj", "gif", "heatmap", "evaluation"):
        if key in summary["files"]:
            console.print(f"  {key:10} {summary['files'][key]}")


def main() -> None:
    parser = argparse.ArgumentParser(description="Run the gnngarment demo end to end.")
    parser.add_argument("--out", type=Path, default=Path("demo_output"))
    parser.add_argument("--quick", action="store_true",
                        help="tiny dataset and run (what the tests use)")
    parser.add_argument("--model", type=Path, default=None,
                        help="checkpoint to animate with (default: the shipped one)")
    arguments = parser.parse_args()
    keep_freed_memory()  # as every gnngarment command (gnngarment/allocator.py)
    configs = REPOSITORY_ROOT / "configs"
    started = time.perf_counter()
    if arguments.quick:
        summary = run(arguments.out, configs / "data" / "tiny.yaml",
                      configs / "train" / "tiny.yaml", arguments.model, attribution_steps=8,
                      motion_seconds=0.5)
    else:
        summary = run(arguments.out, configs / "data" / "demo.yaml",
                      configs / "train" / "demo.yaml", arguments.model)
    _print_summary(summary, arguments.out, time.perf_counter() - started)


if __name__ == "__main__":
    main()
