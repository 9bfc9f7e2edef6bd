"""The one way a command reports bad input (one line on stderr, exit code 2), and the
checks of options and garments that several commands share."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer
from rich.console import Console

#: Exit code for bad input (usage errors share it, as in typer/click).
BAD_INPUT = 2

errors = Console(stderr=True)


def fail(message: str) -> typer.Exit:
    """Print ``message`` as an error and return the exit to raise (``raise fail(...)``)."""
    from rich.markup import escape

    # soft_wrap: one line however long (rich would break it at the terminal width);
    # escaped: rich would drop "[low, high]" or ".[ray]" in a message as a markup tag.
    errors.print(f"[bold red]error:[/] {escape(message)}", highlight=False, soft_wrap=True)
    return typer.Exit(BAD_INPUT)


def check_output_file(option: str, path: Path | None) -> None:
    """Before any work: ``path`` (if given) is not a folder and its folder exists.

    Raises:
        typer.Exit: (after the message) a folder, or a file in a missing folder.
    """
    if path is None:
        return
    if path.is_dir():
        raise fail(f"{option} {path}: is a folder; give a file name")
    if not path.parent.is_dir():
        raise fail(f"{option} {path}: the folder {path.parent} does not exist")


#: Up axes a motion file may be read with (``--motion-up-axis``).
MOTION_UP_AXES = ("auto", "y", "z")


def check_motion_options(fps: float, duration: float, motion_up_axis: str) -> None:
    """``--fps``, ``--duration`` and ``--motion-up-axis`` of the commands that build a
    motion, before any loading.

    Raises:
        typer.Exit: (after the message) a bad value.
    """
    from gnngarment.body.motion_limits import motion_option_problem

    problem = motion_option_problem(fps, duration)
    if problem is not None:
        raise fail(problem)
    if motion_up_axis not in MOTION_UP_AXES:
        raise fail(f"--motion-up-axis must be auto, y or z, got '{motion_up_axis}'")


def refuse_misplaced_garment(console: Console, pos: Any, faces: Any, body: Any,
                             garment_mesh: Path, ignore: bool, fixes: str) -> None:
    """Print every placement finding of the garment on the rest ``body``
    (:class:`~gnngarment.data.body_inputs.BodyShapeInputs`) and refuse it, before the
    long work, when one is an error and ``ignore`` (``--ignore-placement``) is off.

    Args:
        fixes: the command's options that could fix it, for the message.

    Raises:
        typer.Exit: (after the message) the garment is not on the rest body.
    """
    from gnngarment.inference.checks import check_garment_placement

    findings = check_garment_placement(pos, faces, body.rest_vertices, body.faces)
    for finding in findings:
        colour = "red" if finding.severity == "error" else "yellow"
        console.print(f"[{colour}]{finding.severity}:[/] {garment_mesh}: {finding.message}",
                      highlight=False)
    if any(f.severity == "error" for f in findings) and not ignore:
        raise fail(f"{garment_mesh}: the garment is not on the rest body (see above; fix it "
                   f"or pass {fixes})")
