"""The ``gnngarment`` command.

Every command turns bad input (missing file, broken mesh, bad config) into one clear
line on stderr and exit code 2 — never a traceback.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from gnngarment.allocator import keep_freed_memory
from gnngarment.cli.errors import (
    check_motion_options,
    check_output_file,
    fail,
    refuse_misplaced_garment,
)
from gnngarment.threads import use_idle_cores

app = typer.Typer(help="Animate any garment mesh with one learned model.",
                  no_args_is_help=True, add_completion=False)
console = Console()


def _print_version(value: bool) -> None:
    """``--version``: the package version and the shipped checkpoint's id (the first 12
    hex digits of its content hash), then exit."""
    if not value:
        return
    from gnngarment import __version__
    from gnngarment.paths import SHIPPED_MODEL

    try:
        from gnngarment.model.checkpoint import CONTENT_HASH_KEY, load_checkpoint

        model = load_checkpoint(SHIPPED_MODEL).get(CONTENT_HASH_KEY, "")[:12]
    except ValueError as error:
        model = f"unreadable: {error}"
    console.print(f"gnngarment {__version__}; shipped model {SHIPPED_MODEL.name} {model}",
                  highlight=False)
    raise typer.Exit()


@app.callback()
def root(
    version: Annotated[bool, typer.Option(
        "--version", callback=_print_version, is_eager=True,
        help="Print the version and the shipped model's id, then exit.")] = False,
) -> None:
    """Animate any garment mesh with one learned model."""
    # Every command: freed tensors are reused instead of unmapped (gnngarment/allocator.py).
    keep_freed_memory()


def _garment_config(config_path: Path | None, levels: int | None):
    from gnngarment.config import ConfigError, load_config
    from gnngarment.geometry.prepare import GarmentPreparationConfig
    from gnngarment.paths import default_config

    path = config_path or default_config("garment.yaml")
    try:
        if config_path is not None or path.is_file():
            config = load_config(path, GarmentPreparationConfig)
        else:
            config = GarmentPreparationConfig()
    except ConfigError as error:
        raise fail(str(error)) from None
    from gnngarment.model.config import MAX_LEVELS

    if levels is not None:
        if not 0 <= levels <= MAX_LEVELS:
            raise fail(f"--levels must be in 0..{MAX_LEVELS} (what a model can use), got {levels}")
        config.levels = levels
    elif not 0 <= config.levels <= MAX_LEVELS:
        raise fail(f"{path}: key 'levels' must be in 0..{MAX_LEVELS}, got {config.levels}")
    return config


def _attention_paths() -> dict[str, str | None]:
    """Which graph-attention path this machine runs (gnngarment.model.fused_attention):
    for inference (animate) and for training, with the reason for a fallback."""
    from gnngarment.model.fused_attention import attention_path, fallback_reason

    return {"inference": attention_path(), "training": attention_path(grad=True),
            "fallback_reason": fallback_reason() or fallback_reason(grad=True)}


@app.command()
def inspect(
    garment_mesh: Annotated[Path, typer.Argument(help="OBJ, PLY, OFF, STL, glTF or GLB file.")],
    levels: Annotated[int | None, typer.Option(help="Pooling levels (default: config).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print everything as JSON.")] = False,
    config: Annotated[Path | None, typer.Option(help="Garment YAML config.")] = None,
    rest_check: Annotated[bool, typer.Option(
        help="Simulate a few frames of the garment on the (average) rest body and say "
             "whether it is at rest (animate expects it draped; else use animate --drape).")
    ] = False,
    source_body: Annotated[Path | None, typer.Option(
        help="The body mesh the garment was modelled on: report the fit onto the rest "
             "body (as animate --source-body) and rest-check the fitted garment.")] = None,
) -> None:
    """Validate a garment mesh and print its pooling hierarchy and style descriptor."""
    from gnngarment.geometry.errors import MeshError
    from gnngarment.geometry.mesh_io import load_mesh
    from gnngarment.geometry.prepare import prepare_garment

    settings = _garment_config(config, levels)
    start = time.perf_counter()
    try:
        pos, faces = load_mesh(garment_mesh)
        load_seconds = time.perf_counter() - start
        prepared = prepare_garment(pos, faces, settings, source=str(garment_mesh))
    except MeshError as error:
        raise fail(str(error)) from None
    seconds = {"load": load_seconds, **prepared.seconds}
    rest_body = _average_rest_body() if source_body is not None or rest_check else None
    fit = _fit_report(pos, faces, source_body, rest_body) if source_body is not None else None
    if fit is not None:
        pos = fit.pop("pos")
    rest_state = _rest_state(pos, faces, garment_mesh, rest_body) if rest_check else None
    hierarchy = prepared.hierarchy
    # Each component's centre at every level, in that level's numbering.
    centres = [level.centres.tolist() for level in hierarchy.levels]
    attention = _attention_paths()

    if as_json:
        result = {
            "file": str(garment_mesh),
            "vertices": len(pos), "faces": len(faces),
            "components": prepared.report.num_components,
            "findings": prepared.report.findings,
            "levels": [
                {"level": k, "vertices": n, "edges": e,
                 **({"centres": centres[k]} if k < len(centres) else {}),
                 **({"kept": hierarchy.levels[k - 1].kept.tolist()} if k > 0 else {})}
                for k, (n, e) in enumerate(zip(hierarchy.vertex_counts(),
                                               hierarchy.edge_counts(), strict=True))
            ],
            "descriptor": prepared.descriptor.tolist(),
            "seconds": seconds,
            **({"rest_check": rest_state} if rest_state is not None else {}),
            **({"fit": fit} if fit is not None else {}),
            "attention": attention,
        }
        print(json.dumps(result, indent=2))
        return

    console.print(f"[bold]{garment_mesh}[/]: {len(pos)} vertices, {len(faces)} faces, "
                  f"{prepared.report.num_components} component(s)")
    for finding in prepared.report.findings:
        console.print(f"  [yellow]finding:[/] {finding}")
    if not prepared.report.findings:
        console.print("  [green]no findings[/]")
    table = Table(title="pooling hierarchy (Algorithm 1)")
    for column in ("level", "vertices", "edges", "component centres (level numbering)"):
        table.add_column(column)
    for k, (n, e) in enumerate(zip(hierarchy.vertex_counts(), hierarchy.edge_counts(),
                                   strict=True)):
        shown = centres[k] if k < len(centres) else []
        text = ", ".join(map(str, shown[:8])) + (" ..." if len(shown) > 8 else "")
        table.add_row(str(k), str(n), str(e), text or "-")
    console.print(table)
    reason = attention["fallback_reason"]
    console.print(f"  graph attention: {attention['inference']} (inference), "
                  f"{attention['training']} (training)" + (f"; {reason}" if reason else ""))
    counts = hierarchy.vertex_counts()
    stuck = next((k for k in range(1, len(counts)) if counts[k] == counts[k - 1]), None)
    if stuck is not None:
        console.print(f"  [yellow]note:[/] levels {stuck}..{len(counts) - 1} do not shrink "
                      f"any more ({counts[stuck]} vertices): this garment supports at most "
                      f"{stuck - 1} useful level(s)")
    descriptor = prepared.descriptor
    console.print(f"style descriptor ({len(descriptor)} Nyström eigenvalues, largest first): "
                  + " ".join(f"{v:.4g}" for v in descriptor[:8]) + " ...")
    console.print("seconds: " + ", ".join(f"{k} {v:.3f}" for k, v in seconds.items()))
    if fit is not None:
        console.print(f"[yellow]placement:[/] {fit['message']}")
    if rest_state is not None:
        colour = "green" if rest_state["at_rest"] else "yellow"
        console.print(f"[{colour}]rest check:[/] {rest_state['message']}")


#: ``inspect --rest-check``: frames simulated, and the mean move (metres) above which
#: the garment is "not at rest" (a draped garment creeps ~1 mm in that time).
REST_CHECK_FRAMES = 5
REST_CHECK_MOVE = 0.003


def _average_rest_body():
    """The average Anny rest body as :class:`BodyShapeInputs` (what ``inspect`` checks a
    garment against)."""
    from gnngarment.body import AnnyBodyModel
    from gnngarment.data.body_inputs import body_shape_inputs

    body_model = AnnyBodyModel()
    return body_shape_inputs(body_model, body_model.default_shape(), 128)


def _fit_report(pos, faces, source_body: Path, body) -> dict:
    """``inspect --source-body``: the garment fitted onto the rest ``body`` and what the
    fit found (the fitted positions under ``pos``)."""
    from gnngarment.geometry.errors import MeshError
    from gnngarment.geometry.mesh_io import load_mesh
    from gnngarment.inference.placement import place_garment

    try:
        source = load_mesh(source_body)
    except (MeshError, ValueError) as error:
        raise fail(str(error)) from None
    try:
        placed = place_garment(pos, faces, body, source_body=source)
    except ValueError as error:
        raise fail(f"{source_body}: {error}") from None
    alignment = placed.fitted.alignment
    return {"pos": placed.pos, "message": placed.messages[0], "scale": alignment.scale,
            "rotation": alignment.rotation.tolist(),
            "translation_m": alignment.translation.tolist(),
            "registration_error_m": placed.fitted.registration_error}


def _rest_state(pos, faces, garment_mesh: Path, body) -> dict:
    """Simulate :data:`REST_CHECK_FRAMES` frames of the garment on the rest ``body`` (as
    given: metres, Z up) and report how far it moves."""
    from data_prep.simulate import SimulationFailed, drape_garment

    try:
        result = drape_garment(pos, faces, body.rest_vertices, body.faces,
                               max_frames=REST_CHECK_FRAMES)
    except (ValueError, SimulationFailed) as error:
        raise fail(f"{garment_mesh}: the rest check could not simulate it: {error}") from None
    move = result.mean_displacement
    at_rest = move < REST_CHECK_MOVE
    message = (f"{REST_CHECK_FRAMES} simulated frames on the rest body move it "
               f"{1000 * move:.1f} mm (mean): "
               + ("at rest" if at_rest else "not at rest: drape it first (animate --drape, "
                  "or your simulator)"))
    return {"at_rest": bool(at_rest), "mean_move_m": move, "frames": REST_CHECK_FRAMES,
            "message": message}


@app.command()
def prepare(
    config: Annotated[Path | None, typer.Option(help="Dataset YAML (configs/data/*.yaml).")
                      ] = None,
    workers: Annotated[int | None, typer.Option(
        help="Simulation processes (default: cores); with --executor ray, the most tasks at "
             "once (default: the cluster's CPUs).")] = None,
    from_cloth3d: Annotated[Path | None, typer.Option(
        "--from-cloth3d", help="Build the cache from a CLOTH3D folder instead.")] = None,
    smpl_model: Annotated[Path | None, typer.Option(
        help="SMPL model file for both genders (CLOTH3D), or a folder holding "
             "SMPL_FEMALE/SMPL_MALE.pkl|npz: .npz, or a .pkl from a trusted source only (a "
             "pickle can run code).")] = None,
    smpl_model_female: Annotated[Path | None, typer.Option(
        help="SMPL model for CLOTH3D sequences with gender 0 (overrides --smpl-model).")
                                 ] = None,
    smpl_model_male: Annotated[Path | None, typer.Option(
        help="SMPL model for CLOTH3D sequences with gender 1 (overrides --smpl-model).")
                               ] = None,
    output: Annotated[Path | None, typer.Option(help="Cache folder (overrides the config).")
                      ] = None,
    executor: Annotated[str | None, typer.Option(
        help="Where the simulations run: local (a process pool, the default) or ray (Ray "
             "tasks on a cluster; pip install -e '.[ray]'). Overrides the config.")] = None,
    address: Annotated[str | None, typer.Option(
        help="Ray cluster to join with --executor ray: auto, HOST:6379 or "
             "ray://HOST:10001 (default: RAY_ADDRESS, else a `ray start` cluster of this "
             "machine, else a new Ray here).")
                       ] = None,
) -> None:
    """Build (or resume) a dataset: simulate with Newton and write the prepared cache."""
    from gnngarment.config import ConfigError, load_config

    if from_cloth3d is not None:
        from data_prep.cloth3d_build import build_from_cloth3d

        if smpl_model is None and smpl_model_female is None and smpl_model_male is None:
            raise fail("--from-cloth3d needs --smpl-model FILE|FOLDER or --smpl-model-female/"
                       "--smpl-model-male FILE (SMPL is not shipped: get it from "
                       "https://smpl.is.tue.mpg.de)")
        try:
            # Missing or unreadable models, and genders without one, fail before any work.
            report = build_from_cloth3d(from_cloth3d, smpl_model, output or Path("data/cloth3d"),
                                        smpl_model_female=smpl_model_female,
                                        smpl_model_male=smpl_model_male)
        except (ValueError, OSError) as error:  # SMPLModelError is a FileNotFoundError
            raise fail(str(error)) from None
        console.print(report)
        return
    if config is None:
        raise fail("give --config configs/data/<name>.yaml (or --from-cloth3d DIR)")
    if workers is not None and workers < 0:  # else refused only after the bodies are built
        raise fail(f"--workers must be >= 0 (0: one per core), got {workers}")
    from dataclasses import replace

    from data_prep.build import build_dataset
    from data_prep.config import DataConfig
    from data_prep.plan import plan_dataset
    from data_prep.ray_executor import RayMissingError
    from data_prep.simulate import load_simulation_settings

    try:
        settings = load_config(config, DataConfig)
    except ConfigError as error:
        raise fail(str(error)) from None
    if output is not None:
        settings.output = str(output)
    try:  # replace() checks the overridden values as the YAML's are
        settings = replace(settings, executor=executor or settings.executor,
                           ray_address=settings.ray_address if address is None else address)
    except ValueError as error:
        raise fail(f"--executor/--address: {error}") from None
    try:  # what the build checks only once it has taken (and made) the output folder
        plan_dataset(settings)
        load_simulation_settings(settings.simulation)
    except ValueError as error:
        raise fail(f"{config}: {error}") from None
    try:
        report = build_dataset(settings, workers=workers, log=console.print)
    except (RayMissingError, ValueError, OSError) as error:
        raise fail(str(error)) from None
    if report["planned"] and not sum(report["splits"].values()):
        # Every sequence failed (motion_seconds: 1e9 hit an allocation in each): an empty
        # cache is not a build; the reasons are in the report.
        reasons = ", ".join(f"{count} {kind}" for kind, count in
                            (report.get("losses_by_reason") or {}).items()
                            if kind not in ("planned", "lost"))
        raise fail(f"{report['output']}: every one of the {report['planned']} planned "
                   f"sequences was left out ({reasons or 'no reason recorded'}; "
                   f"{report['output']}/build_report.json lists each)")
    console.print(f"[green]done[/] in {report['seconds']:.0f} s: splits {report['splits']}, "
                  f"{len(report['failed_sequences'])} sequence(s) left out; "
                  f"cache in {report['output']}")


@app.command()
def train(
    config: Annotated[Path, typer.Option(help="Training YAML (configs/train/*.yaml).")],
    resume: Annotated[bool, typer.Option(help="Continue from <output>/last.pt.")] = False,
    set_: Annotated[list[str] | None, typer.Option(
        "--set", help="Override a setting, e.g. --set epochs=3 --set model.levels=0.")] = None,
) -> None:
    """Train one model across the garments of a prepared cache (both stages)."""
    import os

    import torch

    from gnngarment.config import ConfigError
    from gnngarment.data import CacheError, PreparedDataset
    from gnngarment.model.checkpoint import load_checkpoint
    from gnngarment.training.loading import load_training_config
    from gnngarment.training.trainer import CHECKPOINT_NAME, RunFolderError, Trainer

    try:
        settings = load_training_config(config, set_)
    except (ConfigError, ValueError) as error:
        raise fail(str(error)) from None
    if resume:  # a missing or corrupt checkpoint is said before any work, not started over
        try:
            load_checkpoint(Path(settings.output) / CHECKPOINT_NAME)
        except ValueError as error:
            raise fail(f"--resume: {error} (drop --resume to start a new run)") from None
    if int(os.environ.get("WORLD_SIZE", "1")) > 1 and not torch.distributed.is_initialized():
        # Launched by torchrun: one process per rank, gloo on CPU (NCCL needs GPUs).
        torch.distributed.init_process_group("gloo")
    try:
        train_split = PreparedDataset(settings.data, "train", settings.model.window)
        validation = PreparedDataset(settings.data, "val", settings.model.window)
    except (CacheError, ValueError) as error:
        raise fail(str(error)) from None
    if len(validation) == 0:
        validation = None
    try:
        trainer = Trainer(settings, train_split, validation)
    except ValueError as error:   # initial_weights that do not fit, a cache for another model
        raise fail(str(error)) from None
    try:
        summary = trainer.fit(resume=resume)
    except (CacheError, RunFolderError, FloatingPointError) as error:
        raise fail(str(error)) from None
    if trainer.rank == 0:
        console.print(f"[green]done[/]: {summary['epochs']} epochs, stage {summary['stage']}; "
                      f"checkpoint {trainer.checkpoint_path()}")
        for switch in summary["switches"]:
            console.print(f"  epoch {switch['epoch']}: {switch['from']} -> {switch['to']} "
                          f"({switch['reason']})")


#: ``--allow-unverified`` of the commands that load a model.
ALLOW_UNVERIFIED_HELP = ("Load a checkpoint that has no content hash (a change to it cannot "
                         "be detected; docs/reliability.md says how to re-hash one).")


@app.command()
def evaluate(
    checkpoint: Annotated[Path, typer.Option(help="Model checkpoint (.pt).")],
    split: Annotated[str, typer.Option(help="Split of the prepared cache.")] = "test",
    data: Annotated[Path | None, typer.Option(
        help="Prepared cache (default: the one the checkpoint was trained on).")] = None,
    json_path: Annotated[Path | None, typer.Option("--json", help="Write the report as JSON.")
                         ] = None,
    markdown: Annotated[Path | None, typer.Option(help="Write the Markdown table.")] = None,
    spurious: Annotated[bool, typer.Option(help="Run the spurious-correlation test.")] = True,
    allow_unverified: Annotated[bool, typer.Option(help=ALLOW_UNVERIFIED_HELP)] = False,
) -> None:
    """Report E_verts, E_norm, collision rate, Hausdorff, STED and the spurious-correlation
    test per garment type, for the model and the body-skinning baseline: of the output
    after collision resolution as animate gives it, and raw_* of the output before it;
    and, for a cache built with layered outfits, per garment E_verts and inter-garment
    penetration of each outfit."""
    import json as json_module

    from gnngarment.data import CacheError, PreparedDataset
    from gnngarment.evaluation import evaluate as run_evaluation
    from gnngarment.evaluation import write_report
    from gnngarment.model.checkpoint import load_checkpoint, load_model

    for option, path in (("--json", json_path), ("--markdown", markdown)):
        check_output_file(option, path)
    use_idle_cores()
    try:
        model = load_model(checkpoint, allow_unverified)
        if data is None:
            data = Path(json_module.loads(load_checkpoint(
                checkpoint, allow_unverified)["training_config"])["data"])
        dataset = PreparedDataset(data, split, model.config.window)
    except (CacheError, ValueError, KeyError) as error:
        raise fail(str(error)) from None
    from tqdm import tqdm

    from data_prep.posed_bodies import (
        synthetic_body_inputs,
        synthetic_body_meshes,
        synthetic_skinning_weights,
    )
    from gnngarment.evaluation.outfits import outfit_names

    # Sequences, then the split's layered outfits (a cache built with `outfits`).
    bar = tqdm(total=len(dataset) + len(outfit_names(dataset)), desc=f"evaluating {split}",
               unit="sequence")
    try:  # a cache file is hash-checked when first read: a swapped one fails here
        report = run_evaluation({"ours": model}, dataset, spurious=spurious,
                                progress=lambda name: bar.update(1),
                                body_meshes=synthetic_body_meshes(data),
                                collisions=_collision_settings(),
                                body_skinning_weights=synthetic_skinning_weights(data),
                                outfit_body_inputs=synthetic_body_inputs(data))
    except CacheError as error:
        raise fail(str(error)) from None
    bar.close()
    console.print(report.to_markdown())
    write_report(report, markdown, json_path)


def _collision_settings():
    """``configs/collisions.yaml`` (or the dataclass defaults it mirrors, where the file is
    absent), or a clear failure."""
    from gnngarment.config import ConfigError, load_config
    from gnngarment.geometry.body_collisions import CollisionSettings
    from gnngarment.paths import default_config

    path = default_config("collisions.yaml")
    if not path.is_file():
        return CollisionSettings()
    try:
        return load_config(path, CollisionSettings)
    except ConfigError as error:
        raise fail(str(error)) from None


def _load_body_and_motion(body_shape: str, motion: str, fps: float, duration: float,
                          joint_map: Path | None = None, motion_up_axis: str = "auto",
                          lead_in: float = 0.0):
    """Anny body, its shape and a motion (procedural name or file, retargeted onto this
    shape's rest skeleton, after ``lead_in`` seconds from the rest pose), or a clear
    failure."""
    from gnngarment.body import AnnyBodyModel, MotionError, load_motion_for_body

    body_model = AnnyBodyModel()
    try:
        shape = body_model.parse_shape(body_shape)
    except (ValueError, OSError) as error:
        raise fail(f"--body-shape {body_shape}: {error}") from None
    try:
        motion_value = load_motion_for_body(motion, body_model, shape, fps=fps,
                                            joint_map=joint_map, up_axis=motion_up_axis,
                                            lead_in=lead_in, duration=duration)
    except (MotionError, ValueError, OSError) as error:
        raise fail(f"--motion {motion}: {error}") from None
    return body_model, shape, motion_value


def _export_name(garment_mesh: Path) -> str:
    """The export file stem: the garment file's, with anything but letters, digits and
    ``-_.`` replaced by ``_`` (``my dress.obj`` → ``my_dress``)."""
    name = "".join(c if c.isalnum() or c in "-_." else "_" for c in garment_mesh.stem)
    return name.lstrip(".") or "garment"


def _refuse_outputs_over_inputs(out: Path, name: str, formats: list[str], include_body: bool,
                                inputs: list[Path | None]) -> None:
    from gnngarment.inference.export.export import export_paths, listed_export_files
    from gnngarment.inference.output_folder import check_outputs_spare_inputs

    files, folders = export_paths(out, name, formats, include_body)
    # An earlier export's files that this one does not write are removed by it.
    for path in listed_export_files(out, name):
        (folders if path.name == f"{name}_obj" else files).append(path)
    try:
        check_outputs_spare_inputs(files, folders, [p for p in inputs if p is not None])
    except ValueError as error:
        raise fail(str(error)) from None


def _hold_output_folder(context: typer.Context, out: Path):
    """Before any work: lock ``out`` for the rest of the command (released when it ends,
    or by the kernel if it is killed). A second ``animate`` into the same folder is
    refused at once, naming the holder, instead of both running and mixing their frames;
    a folder that cannot be created or written is reported before the inference."""
    from gnngarment.inference.output_folder import check_writable_folder
    from gnngarment.io.atomic import FolderLock

    try:
        check_writable_folder(out)  # says why (a file, a place that cannot be written)
        return context.with_resource(FolderLock(out, "export"))  # or who holds it
    except OSError as error:
        raise fail(f"--out {out}: {error}") from None


def _check_animate_options(fps: float, duration: float, motion_up_axis: str,
                           formats: list[str], fix_units: str, up_axis: str,
                           scale: float | None, offset: tuple[float, float, float] | None,
                           influences: int) -> None:
    """``animate``'s options, before any loading: some are otherwise only read after the
    animation (``--format``, ``--influences``) or once the body is built."""
    import math

    from gnngarment.inference.checks import UNIT_SCALES
    from gnngarment.inference.export import FORMATS

    check_motion_options(fps, duration, motion_up_axis)
    unknown = [name for name in formats if name not in FORMATS]
    if unknown or not formats:
        raise fail(f"--format: unknown {unknown or 'empty list'}; choose from "
                   f"{', '.join(FORMATS)}")
    if fix_units not in ("auto", *UNIT_SCALES):
        raise fail(f"--fix-units must be auto, {', '.join(UNIT_SCALES)}, got '{fix_units}'")
    if up_axis not in ("z", "y", "auto"):
        raise fail(f"--up-axis must be z, y or auto, got '{up_axis}'")
    if scale is not None and not (scale > 0 and math.isfinite(scale)):
        raise fail(f"--scale must be a finite number > 0, got {scale}")
    if offset is not None and not all(math.isfinite(value) for value in offset):
        raise fail(f"--offset must be 3 finite numbers (metres), got {list(offset)}")
    if not 1 <= influences <= 8:  # the range of the glb writer's static skin
        raise fail(f"--influences must be in 1..8, got {influences}")


#: ``--lead-in``'s help; the seconds themselves: :func:`_lead_in_seconds`.
LEAD_IN_HELP = (
    "Seconds of a smooth blend from the rest pose (the garment's draped pose) into the "
    "motion's first pose, in front of it; a file's T-pose reference frame is dropped "
    "first. Default: 0.5 for a motion file, 0 for a procedural motion (they start at "
    "rest). The exports include these frames: the first round(seconds * fps) frames are "
    "the lead-in, the clip starts after them; 0 exports the clip as loaded "
    "(docs/motions.md).")


def _lead_in_seconds(motion: str, lead_in: float | None) -> float:
    """``--lead-in``, checked before any loading, or its default for ``motion``
    (:func:`~gnngarment.body.motion_io.default_lead_in`)."""
    from gnngarment.body.lead_in import MAX_LEAD_IN_SECONDS, check_lead_in_seconds
    from gnngarment.body.motion import MotionError
    from gnngarment.body.motion_io import default_lead_in

    if lead_in is None:
        return default_lead_in(motion)
    try:
        return check_lead_in_seconds(lead_in)
    except MotionError:
        raise fail(f"--lead-in must be a finite number of seconds in "
                   f"[0, {MAX_LEAD_IN_SECONDS:g}], got {lead_in}") from None


def _lead_in_note(seconds: float, fps: float) -> str:
    """Which of the animated frames are the lead-in, for the summary line."""
    from gnngarment.body.lead_in import lead_in_frames

    count = lead_in_frames(seconds, fps)
    if count == 0:
        return ""
    return (f"; frames 0-{count - 1} are the {seconds:g} s lead-in from the rest pose, "
            f"the motion starts at frame {count}")


def _place(pos, faces, body_inputs, units: str, up_axis: str, scale: float | None,
           offset, source, named: Path):
    """``place_garment`` with the command's options, or a clear failure naming ``named``
    (the source body when one is given, else the garment file)."""
    from gnngarment.inference.placement import place_garment

    try:
        return place_garment(pos, faces, body_inputs, units=units, up_axis=up_axis,
                             scale=scale, offset=None if offset is None else list(offset),
                             source_body=source)
    except ValueError as error:
        raise fail(f"{named}: {error}") from None


def _drape(placed, faces, body_inputs, garment_mesh: Path):
    """``animate --drape``: the garment settled on the rest body, with a progress bar, or
    a clear failure."""
    return _drape_outfit([placed], [faces], body_inputs, [garment_mesh])[0]


def _drape_outfit(placed: list, faces: list, body_inputs, garment_meshes: list[Path]) -> list:
    """``animate --drape`` of one garment or an outfit (every garment in one simulation),
    with a progress bar, or a clear failure naming the files."""
    from tqdm import tqdm

    from data_prep.simulate import SimulationFailed
    from gnngarment.inference.placement import drape_outfit_on_rest_body

    bar = tqdm(desc="draping on the rest body", unit="frame")

    def advance(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.n)

    try:
        return drape_outfit_on_rest_body(placed, faces, body_inputs, progress=advance)
    except (ValueError, SimulationFailed) as error:
        names = ", ".join(str(path) for path in garment_meshes)
        raise fail(f"{names}: the drape failed: {error}") from None
    finally:
        bar.close()


@app.command()
def animate(
    context: typer.Context,
    garment_meshes: Annotated[list[Path], typer.Argument(
        help="Garment mesh in the rest body's frame; several garments are animated as one "
             "outfit (docs/outfits.md).")],
    out: Annotated[Path, typer.Option(help="Output folder.")] = Path("animated"),
    checkpoint: Annotated[Path | None, typer.Option(
        help="Model checkpoint (default: the shipped models/gnngarment-small.pt).")] = None,
    body_shape: Annotated[str, typer.Option(
        help="Anny preset name or a .json/.yaml phenotype file.")] = "average",
    motion: Annotated[str, typer.Option(
        help="Procedural motion name (gnngarment motions) or .npz/.bvh/info.mat.")] = "walk",
    duration: Annotated[float, typer.Option(help="Seconds of a procedural motion.")] = 2.0,
    fps: Annotated[float, typer.Option(help="Frames per second.")] = 30.0,
    joint_map: Annotated[Path | None, typer.Option(
        help="BVH only: JSON/YAML file mapping canonical joint names (pelvis, L_hip, ...) to "
             "the BVH's joint names (docs/motions.md).")] = None,
    motion_up_axis: Annotated[str, typer.Option(
        help="Up axis of a .npz/.bvh motion: auto, y or z.")] = "auto",
    formats: Annotated[str, typer.Option("--format", help="Comma list: obj,pc2,glb,gif.")
                       ] = "obj,pc2,glb,gif",
    body: Annotated[bool, typer.Option(help="Also export the posed body.")] = True,
    fix_units: Annotated[str, typer.Option(
        "--fix-units", help="Garment units: auto, m, cm or mm.")] = "auto",
    up_axis: Annotated[str, typer.Option(help="Garment up axis: z, y or auto.")] = "z",
    scale: Annotated[float | None, typer.Option(
        help="Metres per unit of the garment file (instead of --fix-units).")] = None,
    offset: Annotated[tuple[float, float, float] | None, typer.Option(
        help="Move the garment by X Y Z metres (rest body frame, Z up) after the scale "
             "and turn.")] = None,
    source_body: Annotated[Path | None, typer.Option(
        help="The body mesh the garment was modelled on (any topology, units, up axis; "
             "T-pose): the garment is fitted from it onto the rest body.")] = None,
    drape: Annotated[bool, typer.Option(
        help="Settle the garment on the rest body with the reference simulator first "
             "(for a garment that is not draped yet).")] = False,
    ignore_placement: Annotated[bool, typer.Option(
        help="Animate even if the garment does not sit on the body.")] = False,
    influences: Annotated[int, typer.Option(help="Joints per vertex in the glb skin.")] = 4,
    resolve_collisions: Annotated[bool, typer.Option(
        help="Move garment vertices out of the body (closer than epsilon, "
             "configs/collisions.yaml), the rest garment and every frame.")] = True,
    lead_in: Annotated[float | None, typer.Option(help=LEAD_IN_HELP)] = None,
    allow_unverified: Annotated[bool, typer.Option(help=ALLOW_UNVERIFIED_HELP)] = False,
    layers: Annotated[str | None, typer.Option(
        help="Outfits: the garments' names (file stems), innermost first, comma-separated "
             "(default: inferred at rest from which lies outside where they overlap).")
                      ] = None,
    split_parts: Annotated[bool, typer.Option(
        help="Outfits: animate each connected part of a file as its own garment "
             "(<stem>_1, <stem>_2, ...; a top and a bottom saved in one file).")] = False,
) -> None:
    """Animate a garment mesh (or an outfit of several) on a body and motion; write
    OBJ/PC2/glb/GIF."""
    if len(garment_meshes) > 1 or split_parts or layers is not None:
        return _animate_outfit(
            context, garment_meshes, out, checkpoint, body_shape, motion, duration, fps,
            joint_map, motion_up_axis, formats, body, fix_units, up_axis, scale, offset,
            source_body, drape, ignore_placement, influences, resolve_collisions, lead_in,
            allow_unverified, layers, split_parts)
    garment_mesh = garment_meshes[0]
    from tqdm import tqdm

    from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
    from gnngarment.geometry.errors import MeshError
    from gnngarment.geometry.mesh_io import load_mesh, load_textured_mesh
    from gnngarment.geometry.validation import validate_mesh
    from gnngarment.inference.animate import animate as run_animation
    from gnngarment.inference.animation_memory import animation_memory_problem
    from gnngarment.inference.export import export_animation
    from gnngarment.model.checkpoint import load_model
    from gnngarment.paths import SHIPPED_MODEL

    format_list = [f.strip() for f in formats.split(",")]
    _check_animate_options(fps, duration, motion_up_axis, format_list, fix_units, up_axis,
                           scale, offset, influences)
    lead_in_seconds = _lead_in_seconds(motion, lead_in)
    checkpoint = checkpoint or SHIPPED_MODEL
    _refuse_outputs_over_inputs(out, _export_name(garment_mesh), format_list, body,
                                [garment_mesh, checkpoint, source_body, joint_map,
                                 Path(motion), Path(body_shape)])
    use_idle_cores()
    try:
        model = load_model(checkpoint, allow_unverified)
        pos, faces, uv, uv_faces = load_textured_mesh(garment_mesh)
        # Before the placement reads the faces (an index out of range was a traceback).
        validate_mesh(pos, faces, str(garment_mesh))
        source = None if source_body is None else load_mesh(source_body)
    except (MeshError, ValueError) as error:
        raise fail(str(error)) from None
    body_model, shape, motion_value = _load_body_and_motion(body_shape, motion, fps, duration,
                                                            joint_map, motion_up_axis,
                                                            lead_in_seconds)
    # Before the drape and the inference: frames x vertices can exceed the free memory
    # even with each option within its limit.
    problem = animation_memory_problem(len(motion_value), len(pos))
    if problem:
        raise fail(problem)
    body_inputs = body_shape_inputs(body_model, shape, model.config.body_vertices)
    placed = _place(pos, faces, body_inputs, fix_units, up_axis, scale, offset, source,
                    source_body or garment_mesh)
    # The output folder is taken before the long work: the drape, else the inference (a
    # garment refused by the placement check then leaves no folder or lock file behind).
    lock = _hold_output_folder(context, out) if drape else None
    if drape:
        placed = _drape(placed, faces, body_inputs, garment_mesh)
    pos = placed.pos
    for message in placed.messages:
        console.print(f"[yellow]placement:[/] {message}")
    refuse_misplaced_garment(console, pos, faces, body_inputs, garment_mesh, ignore_placement,
                             "--source-body, --fix-units/--scale, --up-axis, --offset, or "
                             "--ignore-placement")
    if lock is None:
        lock = _hold_output_folder(context, out)
    frames = body_motion_inputs(body_model, shape, motion_value, model.config.body_vertices)
    bar = tqdm(total=len(motion_value), desc="animating", unit="frame")

    def advance(done: int, total: int) -> None:
        bar.update(done - bar.n)

    try:
        animation = run_animation(model, pos, faces, body_inputs, frames, source=str(garment_mesh),
                                  progress=advance, resolve_collisions=resolve_collisions,
                                  collisions=_collision_settings() if resolve_collisions
                                  else None)
    except MeshError as error:
        raise fail(str(error)) from None
    bar.close()
    if animation.welded:
        console.print(f"[yellow]welded:[/] {animation.welded} of {len(pos)} vertices coincide "
                      "with another (one per triangle corner or seam side); the network ran "
                      "on the welded mesh, the exports keep the file's vertex order")
    animation.uv, animation.uv_faces = uv, uv_faces  # the exports carry the input's UVs
    stages: dict[str, tqdm] = {}

    def exported(stage: str, done: int, total: int) -> None:
        if stage not in stages:
            stages[stage] = tqdm(total=total, desc=f"writing {stage}", unit="file")
        stages[stage].update(done - stages[stage].n)

    try:
        paths = export_animation(
            animation, out, _export_name(garment_mesh),
            formats=format_list, include_body=body,
            max_influences=influences, progress=exported, lock=lock)
    except (ValueError, OSError) as error:
        raise fail(str(error)) from None
    for stage_bar in stages.values():
        stage_bar.close()
    seconds = animation.seconds
    if animation.collisions is not None and animation.rest_collisions is not None:
        stats, rest = animation.collisions, animation.rest_collisions
        console.print(f"collisions: rest garment {int(rest.close[0])} vertices moved out of "
                      f"the body; frames {int((stats.close > 0).sum())} of {len(stats.close)} "
                      f"corrected, {stats.close.mean():.0f} vertices per frame on average "
                      f"(largest push {1000 * stats.max_push.max():.1f} mm, "
                      f"{seconds['collisions']:.2f} s)")
    console.print(f"[green]animated[/] {len(motion_value)} frames "
                  f"(context {seconds['context']:.2f} s, frames {seconds['frames']:.2f} s)"
                  f"{_lead_in_note(lead_in_seconds, fps)}; wrote:")
    for key, path in paths.items():
        console.print(f"  {key}: {path}")


def _register_commands() -> None:
    from gnngarment.cli.attribute import register as register_attribution
    from gnngarment.cli.benchmark import register as register_benchmark
    from gnngarment.cli.body import register as register_body

    register_benchmark(app)  # first: `--help` lists it after animate, as it always did
    register_body(app)
    register_attribution(app)


_register_commands()


def main() -> None:
    """Console-script entry point."""
    app()



#: Stem of an outfit's glb, preview and manifest.
OUTFIT_NAME = "outfit"


def _outfit_garments(paths: list[Path], split_parts: bool):
    """``(name, pos, faces, file)`` per garment of the files (each connected part its own
    with ``split_parts``), or a clear failure."""
    from gnngarment.geometry.errors import MeshError
    from gnngarment.geometry.garment_layers import connected_parts, part_mesh
    from gnngarment.geometry.mesh_io import load_mesh
    from gnngarment.geometry.validation import validate_mesh

    garments = []
    for path in paths:
        try:
            pos, faces = load_mesh(path)
            validate_mesh(pos, faces, str(path))
        except (MeshError, ValueError) as error:
            raise fail(str(error)) from None
        stem = _export_name(path)
        parts = connected_parts(faces, len(pos)) if split_parts else [None]
        if split_parts and len(parts) == 1:
            console.print(f"[yellow]outfit:[/] {path} has one connected part")
        for number, part in enumerate(parts, start=1):
            part_pos, part_faces = (pos, faces) if len(parts) == 1 else part_mesh(pos, faces,
                                                                                 part)
            name = stem if len(parts) == 1 else f"{stem}_{number}"
            garments.append((name, part_pos, part_faces, path))
    names = [name for name, *_ in garments]
    for name in names:
        if names.count(name) > 1 or name == OUTFIT_NAME:
            raise fail(f"{name}: two garments of the outfit (or the outfit itself) would "
                       "share this name: rename a file")
    return garments


def _animate_outfit(context, paths, out, checkpoint, body_shape, motion, duration, fps,
                    joint_map, motion_up_axis, formats, body, fix_units, up_axis, scale,
                    offset, source_body, drape, ignore_placement, influences,
                    resolve_collisions, lead_in, allow_unverified, layers, split_parts
                    ) -> None:
    """``animate`` of several garments (or the parts of one file) as one outfit."""
    from tqdm import tqdm

    from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
    from gnngarment.geometry.errors import MeshError
    from gnngarment.geometry.garment_layers import LayerOrderError
    from gnngarment.geometry.mesh_io import load_mesh
    from gnngarment.inference.animation_memory import animation_memory_problem
    from gnngarment.inference.export.outfit_export import export_outfit, outfit_paths
    from gnngarment.inference.outfit import OutfitGarment, animate_outfit
    from gnngarment.inference.output_folder import check_outputs_spare_inputs
    from gnngarment.model.checkpoint import load_model
    from gnngarment.paths import SHIPPED_MODEL

    format_list = [f.strip() for f in formats.split(",")]
    _check_animate_options(fps, duration, motion_up_axis, format_list, fix_units, up_axis,
                           scale, offset, influences)
    lead_in_seconds = _lead_in_seconds(motion, lead_in)
    checkpoint = checkpoint or SHIPPED_MODEL
    garments = _outfit_garments(list(paths), split_parts)
    names = [name for name, *_ in garments]
    layer_names = None if layers is None else [n.strip() for n in layers.split(",")]
    if layer_names is not None and sorted(layer_names) != sorted(names):
        raise fail(f"--layers {layers}: must name every garment of the outfit once "
                   f"({', '.join(names)})")
    inputs = [*paths, checkpoint, source_body, joint_map, Path(motion), Path(body_shape)]
    for name in names:
        _refuse_outputs_over_inputs(out, name, format_list, body, inputs)
    try:
        check_outputs_spare_inputs(outfit_paths(out, OUTFIT_NAME, format_list), [],
                                   [p for p in inputs if p is not None])
    except ValueError as error:
        raise fail(str(error)) from None
    use_idle_cores()
    try:
        model = load_model(checkpoint, allow_unverified)
        source = None if source_body is None else load_mesh(source_body)
    except (MeshError, ValueError) as error:
        raise fail(str(error)) from None
    body_model, shape, motion_value = _load_body_and_motion(body_shape, motion, fps, duration,
                                                            joint_map, motion_up_axis,
                                                            lead_in_seconds)
    problem = animation_memory_problem(len(motion_value),
                                       sum(len(pos) for _, pos, _, _ in garments))
    if problem:
        raise fail(problem)
    body_inputs = body_shape_inputs(body_model, shape, model.config.body_vertices)
    placed = []
    for name, pos, faces, path in garments:
        one = _place(pos, faces, body_inputs, fix_units, up_axis, scale, offset, source,
                     source_body or path)
        for message in one.messages:
            console.print(f"[yellow]placement ({name}):[/] {message}")
        placed.append(one)
    lock = _hold_output_folder(context, out) if drape else None
    if drape:  # every garment in one simulation, with the simulator's self-contact
        placed = _drape_outfit(placed, [faces for _, _, faces, _ in garments], body_inputs,
                               [path for _, _, _, path in garments])
        for (name, *_), one in zip(garments, placed, strict=True):
            console.print(f"[green]{name}:[/] {one.messages[-1]}")
    outfit = []
    for (name, _, faces, path), one in zip(garments, placed, strict=True):
        refuse_misplaced_garment(console, one.pos, faces, body_inputs, path, ignore_placement,
                                 "--source-body, --fix-units/--scale, --up-axis, --offset, "
                                 "or --ignore-placement")
        outfit.append(OutfitGarment(name=name, pos=one.pos, faces=faces))
    if lock is None:
        lock = _hold_output_folder(context, out)
    frames = body_motion_inputs(body_model, shape, motion_value, model.config.body_vertices)
    bar = tqdm(total=len(motion_value) * len(outfit), desc="animating", unit="frame")
    try:
        result = animate_outfit(model, outfit, body_inputs, frames, layers=layer_names,
                                progress=lambda done, total: bar.update(done - bar.n),
                                resolve_collisions=resolve_collisions,
                                collisions=_collision_settings() if resolve_collisions
                                else None, layer_settings=_layer_settings())
    except (LayerOrderError, MeshError) as error:
        raise fail(str(error)) from None
    bar.close()
    how = ("as given" if layer_names is not None else "read at rest" if result.relations
           else "no two garments overlap at rest: the order given")
    console.print(f"layers (innermost first, {how}): "
                  + ", ".join(result.names[index] for index in result.order))
    for index, share in result.penetration.items():
        stats = result.layer_stats.get(index)
        push = ""
        if stats is not None:
            rest_push = result.rest_layer_stats[index].max_push.max()
            push = (f", largest push {1000 * stats.max_push.max():.1f} mm per frame (rest "
                    f"{1000 * rest_push:.1f} mm)")
        raw = 100 * result.penetration_raw[index].mean()
        console.print(f"{result.names[index]}: {raw:.2f} % of its vertices through the "
                      f"garment beneath in the network's output, {100 * share.mean():.2f} % "
                      f"after resolution{push}")
    try:
        written = export_outfit(result, out, OUTFIT_NAME, formats=format_list,
                                include_body=body, max_influences=influences, lock=lock)
    except (ValueError, OSError) as error:
        raise fail(str(error)) from None
    console.print(f"[green]animated[/] {len(result.names)} garments, {len(motion_value)} "
                  f"frames (layers {result.seconds['layers']:.2f} s)"
                  f"{_lead_in_note(lead_in_seconds, fps)}; wrote:")
    for key, path in written.items():
        console.print(f"  {key}: {path}")


def _layer_settings():
    """``configs/layers.yaml`` (or the dataclass defaults it mirrors), or a clear failure."""
    from gnngarment.config import ConfigError, load_config
    from gnngarment.geometry.garment_layers import LayerSettings
    from gnngarment.paths import default_config

    path = default_config("layers.yaml")
    if not path.is_file():
        return LayerSettings()
    try:
        return load_config(path, LayerSettings)
    except (ConfigError, ValueError) as error:
        raise fail(f"{path}: {error}") from None
