"""``gnngarment benchmark-accuracy``: train and evaluate ours and the baselines on the same
data with the same budget, and write the comparison table (into the run folder by
default; docs/results.md quotes such tables).

An experiment runner, not a metric: it drives the trainer, so it lives beside the CLI
(which may import everything) rather than in :mod:`gnngarment.evaluation`."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from gnngarment.cli.errors import check_output_file, fail
from gnngarment.data.dataset import PreparedDataset
from gnngarment.evaluation.evaluate import METRICS, BodyMeshes, evaluate
from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.model.checkpoint import load_model
from gnngarment.training.config import TrainingConfig
from gnngarment.training.trainer import CHECKPOINT_NAME, SUPERVISED_CHECKPOINT_NAME, Trainer

#: name → the model settings it changes; every variant shares all other settings
#: (the skinning-weight prior of the config included, except for the paper's head).
VARIANTS: dict[str, dict[str, Any]] = {
    "ours (2 levels)": {"levels": 2, "pooling": "structure"},
    "ours, paper's weight head": {"levels": 2, "pooling": "structure", "weight_prior": "none"},
    "single level": {"levels": 0, "pooling": "structure"},
    "TopKPool": {"levels": 2, "pooling": "topk"},
    "SAGPool": {"levels": 2, "pooling": "sag"},
    "ASAPool": {"levels": 2, "pooling": "asap"},
}


def run_benchmark(config: TrainingConfig, output: Path, variants: list[str] | None = None,
                  split: str = "test", command: str = "",
                  body_meshes: BodyMeshes | None = None,
                  body_skinning_weights: np.ndarray | None = None) -> dict[str, Any]:
    """Train every variant with ``config`` (levels/pooling changed only), evaluate each
    before and after the physics stage, and write ``output`` (Markdown). ``body_meshes``
    gives the posed body meshes the evaluation resolves collisions against
    (:func:`~gnngarment.evaluation.evaluate.evaluate`)."""
    names = variants or list(VARIANTS)
    # method → {garment type or "all" → metrics}, body skinning first once evaluated.
    results: dict[str, dict[str, dict[str, float]]] = {}
    seconds: dict[str, float] = {}
    lbs: dict[str, dict[str, float]] | None = None
    for name in names:
        folder = "".join(c for c in name.replace(" ", "_") if c.isalnum() or c == "_")
        variant = replace(config, output=str(Path(config.output) / folder),
                          model=replace(config.model, **VARIANTS[name]))
        started = time.perf_counter()
        train = PreparedDataset(variant.data, "train", variant.model.window)
        trainer = Trainer(variant, train, None, progress=True)
        trainer.fit(resume=True)
        seconds[name] = time.perf_counter() - started
        test = PreparedDataset(variant.data, split, variant.model.window)
        run_folder = Path(variant.output)
        for label, checkpoint in (("supervised", SUPERVISED_CHECKPOINT_NAME),
                                  ("+ physics", CHECKPOINT_NAME)):
            path = run_folder / checkpoint
            if not path.is_file():
                continue
            report = evaluate({name: load_model(path)}, test, body_skinning=lbs is None,
                              body_meshes=body_meshes,
                              body_skinning_weights=body_skinning_weights)
            results[f"{name}, {label}"] = report.results[name]
            if lbs is None and "body skinning (draped template)" in report.results:
                lbs = report.results["body skinning (draped template)"]
    if lbs is not None:
        results = {"body skinning (draped template)": lbs, **results}
    rows = {name: values["all"] for name, values in results.items()}
    lines = ["# Accuracy on held-out garments, bodies and motions", "",
             f"Split `{split}` of `{config.data}`; every learned variant trained with the same "
             f"config ({config.epochs} epochs max, same stage rules, seed {config.seed}).", "",
             f"Command: `{command}`" if command else "", "",
             "| method | " + " | ".join(METRICS) + " |", "|" + "---|" * (len(METRICS) + 1)]
    for name, values in rows.items():
        lines.append(f"| {name} | " + " | ".join(f"{values.get(m, float('nan')):.4g}"
                                                  for m in METRICS) + " |")
    types = sorted({t for per_type in results.values() for t in per_type if t != "all"})
    if types:
        lines += ["", "E_verts (mm) by garment type:", "",
                  "| method | " + " | ".join(types) + " |", "|" + "---|" * (len(types) + 1)]
        for name, per_type in results.items():
            lines.append(f"| {name} | " + " | ".join(
                f"{per_type.get(t, {}).get('e_verts_mm', float('nan')):.4g}" for t in types)
                + " |")
    lines += ["", "Training time per variant (s): " + ", ".join(
        f"{k} {v:.0f}" for k, v in seconds.items())]
    atomic_write_bytes(output, ("\n".join(lines) + "\n").encode())
    return {"rows": rows, "seconds": seconds}


def benchmark_command(
    config: Annotated[Path, typer.Option(help="Training YAML shared by every variant.")],
    output: Annotated[Path | None, typer.Option(
        help="Markdown table to write (default: benchmark_accuracy.md in the config's run "
             "folder; never a docs page by default).")] = None,
    variant: Annotated[list[str] | None, typer.Option(help="Only these variants.")] = None,
    split: Annotated[str, typer.Option(help="Evaluated split.")] = "test",
) -> None:
    """Train ours and the pooling/single-level baselines with one budget, evaluate them
    (and body-skinning LBS) before and after the physics stage, write the table."""
    import sys

    from rich.console import Console

    from gnngarment.config import ConfigError
    from gnngarment.training.loading import load_training_config

    unknown = [v for v in variant or [] if v not in VARIANTS]
    if unknown:
        raise fail(f"unknown variant(s) {unknown}; choose from {list(VARIANTS)}")
    try:
        settings = load_training_config(config)
    except (ConfigError, ValueError) as error:
        raise fail(str(error)) from None
    if output is None:
        output = Path(settings.output) / "benchmark_accuracy.md"
    check_output_file("--output", output)  # written only after every variant is trained
    from data_prep.posed_bodies import synthetic_body_meshes, synthetic_skinning_weights
    from gnngarment.data import CacheError

    try:
        body_meshes = synthetic_body_meshes(settings.data)
        skinning_weights = synthetic_skinning_weights(settings.data)
    except CacheError as error:
        raise fail(str(error)) from None
    result = run_benchmark(settings, output, variant, split,
                           command="gnngarment " + " ".join(sys.argv[1:]),
                           body_meshes=body_meshes, body_skinning_weights=skinning_weights)
    Console().print(f"[green]wrote[/] {output}: {len(result['rows'])} rows")


def register(app: typer.Typer) -> None:
    """Add ``benchmark-accuracy`` to ``app``."""
    app.command("benchmark-accuracy")(benchmark_command)
