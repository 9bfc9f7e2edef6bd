"""Heat → colour, shared by the PNG renders and the PLY export so both agree."""

from __future__ import annotations

import numpy as np

#: Colour scales: ``linear`` shows where the mass is, ``log`` shows how far it reaches
#: (the tail over :data:`LOG_DECADES` decades below the maximum).
SCALES = ("linear", "log")
LOG_DECADES = 4.0
DEFAULT_COLORMAP = "inferno"


def normalise_heat(heat: np.ndarray, scale: str = "linear") -> np.ndarray:
    """``(N,)`` heat mapped to ``[0, 1]`` relative to its maximum.

    ``linear``: ``h / max h``. ``log``: ``1 + log10(h / max h) / LOG_DECADES`` clipped
    at 0, so a vertex with a ten-thousandth of the peak is black.

    Raises:
        ValueError: unknown ``scale``, or heat not ``(N,)``, negative or non-finite.
    """
    heat = np.asarray(heat, dtype=np.float64)
    if scale not in SCALES:
        raise ValueError(f"unknown colour scale '{scale}' (expected one of {SCALES})")
    if heat.ndim != 1 or not np.isfinite(heat).all() or (heat < 0).any():
        raise ValueError(f"heat must be a finite, non-negative (N,) array, got shape {heat.shape}")
    peak = heat.max(initial=0.0)
    if peak <= 0.0:
        return np.zeros_like(heat)
    relative = heat / peak
    if scale == "linear":
        return relative
    with np.errstate(divide="ignore"):
        return np.clip(1.0 + np.log10(relative) / LOG_DECADES, 0.0, 1.0)


def heat_colors(values: np.ndarray, colormap: str = DEFAULT_COLORMAP) -> np.ndarray:
    """``(N,)`` values in ``[0, 1]`` → ``(N, 4)`` uint8 RGBA."""
    from matplotlib import colormaps

    rgba = colormaps[colormap](np.clip(np.asarray(values, dtype=np.float64), 0.0, 1.0))
    return np.round(rgba * 255).astype(np.uint8)
