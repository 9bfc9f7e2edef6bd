"""The error of a bad attribution argument, carrying which argument it was."""

from __future__ import annotations


class AttributionArgumentError(ValueError):
    """A bad value of one argument of an attribution call.

    Attributes:
        argument: the parameter's name (``frame_index``, ``vertices``,
            ``target_vertices``, ``radius``), so a caller (the CLI) can name its own
            option for it without parsing the message.
    """

    def __init__(self, argument: str, message: str) -> None:
        super().__init__(message)
        self.argument = argument
