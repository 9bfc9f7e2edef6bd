"""``gnngarment body`` and ``gnngarment motions`` (registered on the main Typer app)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from gnngarment.cli.errors import check_motion_options, fail


def write_rest_body(out: Path, rest, faces: np.ndarray) -> None:
    """``out/rest_body.obj`` (the rest mesh, metres, Z up) and ``out/rest_joints.json``
    (``{joint name: [x, y, z]}`` metres), each written whole or not at all."""
    import json

    from gnngarment.body.skeleton import JOINT_NAMES
    from gnngarment.io.atomic import atomic_write_bytes
    from gnngarment.io.obj import write_obj

    write_obj(out / "rest_body.obj", rest.vertices.numpy(), np.asarray(faces),
              header="rest body (metres, Z up, facing -Y)")
    joints = {name: [round(float(c), 6) for c in position]
              for name, position in zip(JOINT_NAMES, rest.joints.numpy(), strict=True)}
    atomic_write_bytes(out / "rest_joints.json", json.dumps(joints, indent=1).encode())


def body_command(
    out: Annotated[Path, typer.Option("--out", help="Output folder (created).")],
    motion: Annotated[
        str, typer.Option("--motion", help="Procedural motion name or .npz/.bvh/.mat file.")
    ] = "walk",
    shape: Annotated[
        str | None,
        typer.Option("--shape", help="Anny preset or .json/.yaml phenotype file; SMPL betas file."),
    ] = None,
    model: Annotated[str, typer.Option("--model", help="Body model: anny or smpl.")] = "anny",
    smpl_path: Annotated[
        str, typer.Option("--smpl-path", help="SMPL .npz, or a .pkl from a trusted "
                          "source only (a pickle can run code); with --model smpl.")
    ] = "",
    fps: Annotated[float, typer.Option("--fps", help="Output frame rate.")] = 30.0,
    duration: Annotated[
        float, typer.Option("--duration", help="Seconds (procedural motions).")
    ] = 4.0,
    seed: Annotated[
        int | None, typer.Option("--seed", help="Seeded variation of procedural motions.")
    ] = None,
    joint_map: Annotated[
        Path | None, typer.Option("--joint-map", help="BVH only: JSON/YAML file mapping "
                                  "canonical joint names to the BVH's (docs/motions.md).")
    ] = None,
    motion_up_axis: Annotated[
        str, typer.Option("--motion-up-axis", help="Up axis of a .npz/.bvh motion: auto, y, z.")
    ] = "auto",
    rest: Annotated[
        bool, typer.Option("--rest", help="Write only the rest body (rest_body.obj, metres, Z "
                           "up, facing -Y: the frame `animate` expects a garment in) and its "
                           "joints (rest_joints.json), to dress garments on in other tools.")
    ] = False,
) -> None:
    """Pose a body by a motion: OBJ sequence + skeleton preview PNG in --out (or, with
    --rest, the rest body to model garments on)."""
    from rich.console import Console
    from rich.progress import Progress

    from gnngarment.body.config import BodyConfig
    from gnngarment.body.factory import create_body_model
    from gnngarment.body.motion import MotionError
    from gnngarment.body.motion_io import load_motion
    from gnngarment.body.preview import plot_motion_preview
    from gnngarment.body.smpl_model import SMPLModelError
    from gnngarment.inference.export.obj_sequence import write_obj_sequence

    console = Console(stderr=True)
    start = time.perf_counter()
    check_motion_options(fps, duration, motion_up_axis)
    if model not in ("anny", "smpl"):
        raise fail(f"--model must be 'anny' or 'smpl', got '{model}'")
    try:
        motion_data = None if rest else load_motion(
            motion, fps=fps, joint_map=joint_map, up_axis=motion_up_axis,
            **({} if Path(motion).suffix else {"duration": duration, "seed": seed}))
    except MotionError as error:
        raise fail(str(error)) from None
    if motion_data is not None:
        from gnngarment.inference.animation_memory import animation_memory_problem

        problem = animation_memory_problem(motion_data.num_frames, garment_vertices=0)
        if problem:
            raise fail(problem)
    try:
        with console.status(f"loading the {model} body model (first Anny run builds a cache)"):
            body = create_body_model(BodyConfig(model=model, smpl_model_path=smpl_path))
    except (SMPLModelError, ValueError) as error:
        raise fail(str(error)) from None
    try:
        body_shape = body.parse_shape(shape)
    except (ValueError, OSError) as error:
        raise fail(f"--shape {shape}: {error}") from None
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise fail(f"{out}: cannot create the output folder ({error})") from None
    if motion_data is None:
        write_rest_body(out, body.rest(body_shape), body.faces)
        console.print(f"wrote {out / 'rest_body.obj'} and {out / 'rest_joints.json'} (metres, "
                      f"Z up, facing -Y) in {time.perf_counter() - start:.1f} s")
        return
    with console.status(f"posing {motion_data.num_frames} frames"):
        posed = body.pose(motion_data, body_shape)
    vertices = posed.vertices.numpy()
    with Progress(console=console, transient=True) as progress:
        task = progress.add_task("writing OBJ frames", total=len(vertices))
        write_obj_sequence(out, vertices, body.faces, stem="body",
                           progress=lambda done, total: progress.update(task, completed=done))
    preview = plot_motion_preview(motion_data, body.rest(body_shape).joints, out / "skeleton.png")
    console.print(
        f"wrote {len(vertices)} frames ({vertices.shape[1]} vertices) to {out} and "
        f"{preview.name} in {time.perf_counter() - start:.1f} s"
    )


def motions_command() -> None:
    """List the procedural motion library."""
    from rich.console import Console
    from rich.table import Table

    from gnngarment.body.procedural import list_motions

    table = Table("motion", "description", title="procedural motions")
    for name, description in list_motions():
        table.add_row(name, description)
    Console().print(table)


def register(app: typer.Typer) -> None:
    """Add the ``body`` and ``motions`` commands to ``app``."""
    app.command("body")(body_command)
    app.command("motions")(motions_command)
