"""The error raised for a CLOTH3D file or sequence folder that cannot be used."""

from __future__ import annotations


class Cloth3DError(ValueError):
    """A CLOTH3D file is missing, truncated or inconsistent; the message names the file.

    Messages read ``<path>: <problem>`` so a dataset build can log them as they are.
    """
