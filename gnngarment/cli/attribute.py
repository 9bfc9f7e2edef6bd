"""``gnngarment attribute``: attribution heatmaps of a trained model on a garment (the
work is :func:`gnngarment.attribution.heatmap_files.run_attribution`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from gnngarment.attribution.attribution import HEAT_CHANNELS, OUTPUTS, TARGET_KINDS
from gnngarment.attribution.colors import SCALES
from gnngarment.attribution.heatmap_files import run_attribution
from gnngarment.cli.errors import check_motion_options, fail, refuse_misplaced_garment

#: The option a problem found by :func:`run_attribution` comes from (its messages name
#: its own arguments: the frame index, the target vertices, the radius).
#: The option of each attribution argument an AttributionArgumentError may name.
OPTION_OF_ARGUMENT = {"frame_index": "--frame", "vertices": "--vertex",
                      "target_vertices": "--vertex", "radius": "--radius"}


def attribute_command(
    checkpoint: Annotated[Path, typer.Argument(help="Trained model checkpoint (.pt).")],
    garment_mesh: Annotated[Path, typer.Argument(
        help="Garment in the rest body's frame (OBJ, PLY, OFF, STL, glTF, GLB).")],
    out: Annotated[Path, typer.Option("--out", help="Output folder (created).")],
    motion: Annotated[str, typer.Option(
        "--motion", help="Procedural motion name or .npz/.bvh/.mat file.")] = "walk",
    frame: Annotated[int | None, typer.Option(
        "--frame", help="Frame of the motion, its lead-in included, as animate exports "
        "it (default: the middle one).")] = None,
    target: Annotated[str, typer.Option(
        "--target", help="vertex, region or all.")] = "vertex",
    vertex: Annotated[list[int] | None, typer.Option(
        "--vertex", help="Target vertex (default: the one that moves most); repeat for a "
        "region.")] = None,
    radius: Annotated[float | None, typer.Option(
        "--radius", help="Region: every vertex within this geodesic distance (m) of "
        "--vertex.")] = None,
    output: Annotated[str, typer.Option(
        "--output", help="blend_shapes or posed.")] = "blend_shapes",
    n_steps: Annotated[int, typer.Option(
        "--n-steps", help="Gauss-Legendre points (paper: 50).")] = 50,
    heat: Annotated[str, typer.Option(
        "--heat", help="normal (paper) or all channels.")] = "normal",
    scale: Annotated[str, typer.Option("--scale", help="linear or log colours.")] = "linear",
    shape: Annotated[str | None, typer.Option(
        "--shape", help="Anny preset or .json/.yaml phenotype file; SMPL betas file.")] = None,
    body_model: Annotated[str, typer.Option("--body-model", help="anny or smpl.")] = "anny",
    smpl_path: Annotated[str, typer.Option(
        "--smpl-path", help="SMPL .npz, or a .pkl from a trusted source only (a pickle "
                              "can run code); with --body-model smpl.")] = "",
    fps: Annotated[float, typer.Option("--fps", help="Motion frame rate.")] = 30.0,
    duration: Annotated[float, typer.Option(
        "--duration", help="Seconds (procedural motions).")] = 4.0,
    joint_map: Annotated[Path | None, typer.Option(
        "--joint-map", help="BVH only: JSON/YAML file mapping canonical joint names to the "
        "BVH's (docs/motions.md).")] = None,
    motion_up_axis: Annotated[str, typer.Option(
        "--motion-up-axis", help="Up axis of a .npz/.bvh motion: auto, y or z.")] = "auto",
    lead_in: Annotated[float | None, typer.Option(
        "--lead-in", help="Seconds of a blend from the rest pose into the motion, in front "
        "of it, as animate --lead-in (default: 0.5 for a motion file, 0 for a procedural "
        "motion).")] = None,
    source_body: Annotated[Path | None, typer.Option(
        "--source-body", help="The body mesh the garment was modelled on: the garment is "
        "fitted from it onto the rest body first (as animate --source-body).")] = None,
    ignore_placement: Annotated[bool, typer.Option(
        help="Attribute even if the garment does not sit on the rest body (the heatmap of "
        "a misplaced garment explains a deformation it would never get).")] = False,
    allow_unverified: Annotated[bool, typer.Option(
        "--allow-unverified", help="Load a checkpoint that has no content hash (a change to "
        "it cannot be detected; docs/reliability.md).")] = False,
) -> None:
    """Integrated-gradient heatmap (paper Eq. 9) of a predicted deformation: PNG, PLY,
    NPZ and JSON in --out."""
    from rich.console import Console

    from gnngarment.body.config import BodyConfig
    from gnngarment.body.factory import create_body_model
    from gnngarment.body.motion import MotionError
    from gnngarment.body.motion_io import load_motion_for_body
    from gnngarment.body.smpl_model import SMPLModelError
    from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs
    from gnngarment.geometry.errors import MeshError
    from gnngarment.geometry.mesh_io import load_mesh
    from gnngarment.model.checkpoint import load_model

    console = Console(stderr=True)
    if target not in TARGET_KINDS:
        raise fail(f"--target must be one of {', '.join(TARGET_KINDS)}, got '{target}'")
    if output not in OUTPUTS:
        raise fail(f"--output must be one of {', '.join(OUTPUTS)}, got '{output}'")
    from gnngarment.attribution.integrated_gradients import MAX_STEPS

    if not 1 <= n_steps <= MAX_STEPS:
        raise fail(f"--n-steps must be in 1..{MAX_STEPS}, got {n_steps}")
    if heat not in HEAT_CHANNELS:  # else said only after the body and motion are built
        raise fail(f"--heat must be one of {', '.join(HEAT_CHANNELS)}, got '{heat}'")
    if scale not in SCALES:
        raise fail(f"--scale must be one of {', '.join(SCALES)}, got '{scale}'")
    if body_model not in ("anny", "smpl"):
        raise fail(f"--body-model must be 'anny' or 'smpl', got '{body_model}'")
    check_motion_options(fps, duration, motion_up_axis)
    from gnngarment.body.lead_in import MAX_LEAD_IN_SECONDS, check_lead_in_seconds
    from gnngarment.body.motion_io import default_lead_in

    try:
        lead_in = default_lead_in(motion) if lead_in is None else check_lead_in_seconds(lead_in)
    except MotionError:
        raise fail(f"--lead-in must be a finite number of seconds in "
                   f"[0, {MAX_LEAD_IN_SECONDS:g}], got {lead_in}") from None
    from gnngarment.inference.output_folder import check_output_folder

    try:  # now, not when the results are written after the integrated gradients
        check_output_folder(out)
    except OSError as error:
        raise fail(f"--out {out}: {error}") from None
    from gnngarment.threads import use_idle_cores

    use_idle_cores()
    try:
        model = load_model(checkpoint, allow_unverified)
        pos, faces = load_mesh(garment_mesh)
        source = None if source_body is None else load_mesh(source_body)
    except (ValueError, MeshError) as error:
        raise fail(str(error)) from None
    try:
        with console.status(f"loading the {body_model} body model"):
            body = create_body_model(BodyConfig(model=body_model, smpl_model_path=smpl_path))
            body_shape = body.parse_shape(shape)
            count = model.config.body_vertices
            shape_inputs = body_shape_inputs(body, body_shape, count)
            frames = body_motion_inputs(body, body_shape, load_motion_for_body(
                motion, body, body_shape, fps=fps, joint_map=joint_map,
                up_axis=motion_up_axis, lead_in=lead_in, duration=duration), count)
    except (MotionError, SMPLModelError, ValueError) as error:
        raise fail(str(error)) from None
    if source is not None:
        from gnngarment.inference.placement import place_garment

        try:
            placed = place_garment(pos, faces, shape_inputs, source_body=source)
        except ValueError as error:
            raise fail(f"{source_body}: {error}") from None
        pos = placed.pos
        console.print(f"placement: {placed.messages[0]}", highlight=False)
    refuse_misplaced_garment(console, pos, faces, shape_inputs, garment_mesh, ignore_placement,
                             "--source-body or --ignore-placement")
    try:
        with console.status(f"integrated gradients ({n_steps} Gauss-Legendre points)"):
            summary = run_attribution(
                model, pos, faces, shape_inputs, frames, out, frame_index=frame,
                target=target, vertices=vertex or None, radius=radius, output=output,
                n_steps=n_steps, heat=heat, scale=scale, source=str(garment_mesh))
    except (ValueError, MeshError) as error:
        from gnngarment.attribution.errors import AttributionArgumentError

        option = (OPTION_OF_ARGUMENT.get(error.argument)
                  if isinstance(error, AttributionArgumentError) else None)
        raise fail(f"{option}: {error}" if option else str(error)) from None
    console.print(
        f"{summary['target']} {summary['output']}: f(X) = {summary['value']:.4g}, "
        f"f(0) = {summary['baseline_value']:.4g}, completeness delta "
        f"{summary['delta']:.2e} ({summary['relative_delta']:.1e} relative), "
        f"{summary['seconds']:.1f} s")
    console.print("wrote " + ", ".join(summary["files"].values()))


def register(app: typer.Typer) -> None:
    """Add ``attribute`` to ``app``."""
    app.command("attribute")(attribute_command)
