"""The one way a command reports bad input: one line on stderr, exit code 2."""

from __future__ import annotations

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
