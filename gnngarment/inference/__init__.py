"""Animate a garment and export the result.

Imports are lazy (PEP 562) so that light users, such as a reader of exported point
caches through :mod:`gnngarment.inference.export`, do not pay for torch and
torch-geometric.
"""

from __future__ import annotations

from typing import Any

__all__ = ["Animation", "animate", "garment_pair"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        # importlib, not ``from gnngarment.inference import animate``: that statement looks
        # the name up on this package, i.e. calls this function again (RecursionError),
        # and once the submodule is loaded it would hand out the module, not the function.
        import importlib

        module = importlib.import_module("gnngarment.inference.animate")
        # Importing the submodule bound the name ``animate`` to the module: rebind every
        # public name to its object, so later look-ups never reach the module.
        globals().update({public: getattr(module, public) for public in __all__})
        return globals()[name]
    raise AttributeError(f"module 'gnngarment.inference' has no attribute {name!r}")
