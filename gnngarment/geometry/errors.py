"""The error raised for a mesh that cannot be used."""

from __future__ import annotations


class MeshError(ValueError):
    """A garment mesh is missing, unreadable or invalid; the message names the source."""
