"""Animate a garment and export the result.

Imports are lazy (PEP 562) so that light users such as ``data_prep.cloth3d``, which only
needs the point-cache writer, do not pay for torch and torch-geometric.
"""

from __future__ import annotations

from typing import Any

__all__ = ["Animation", "animate", "garment_pair"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from gnngarment.inference import animate as module

        return getattr(module, name)
    raise AttributeError(f"module 'gnngarment.inference' has no attribute {name!r}")
