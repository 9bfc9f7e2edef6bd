"""The design seen from the front: its silhouette on a frontal (X, Z) grid.

Seen from the front, a garment around a body in T- or A-pose is a flat region Ω
(shirt: a T; trousers: an upside-down U). We find Ω from the implicit design
(:class:`~data_prep.garments.shapes.Design`) on a 1–2 cm grid: a point is in a panel's
Ω when the line through it along Y enters the garment's solid and no cut removes the
point where that panel's surface is (front and back differ only where a cut is
tilted, e.g. a neckline deeper in front). The same depth maps place pattern points on
the surface (:func:`lift_on_grid`) and estimate its area (:func:`surface_area`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from data_prep.garments.errors import PatternError
from data_prep.garments.shapes import Design

GRID = 0.01  # metres: default resolution of the silhouette grid
Y_STEP = 0.02  # metres: sampling step along Y when looking for the solid


@dataclasses.dataclass
class Silhouette:
    """The design seen along Y on a grid ``x (W,)`` × ``z (H,)``, sampled at depths
    ``ys (M,)``: ``inside (H, W)`` the union field's minimum along Y, ``fold_y`` where it
    is (the seam depth), ``front_y``/``back_y`` where the surface is first met from the
    front/back, and ``region[side] (H, W)`` the field of that panel's Ω (negative
    inside): the union minimum or a cut evaluated on that panel's surface, whichever is
    larger. Front and back differ only where a cut is tilted (a neckline deeper in
    front)."""

    x: np.ndarray
    z: np.ndarray
    ys: np.ndarray
    inside: np.ndarray
    fold_y: np.ndarray
    front_y: np.ndarray
    back_y: np.ndarray
    region: dict[int, np.ndarray]


def _along_y(design: Design, xz: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """``(P, M)`` field values on the Y lines through ``xz (P, 2)`` at depths ``ys (M,)``."""
    points = np.empty((len(xz), len(ys), 3))
    points[..., 0] = xz[:, None, 0]
    points[..., 1] = ys[None, :]
    points[..., 2] = xz[:, None, 1]
    return design.field(points.reshape(-1, 3)).reshape(len(xz), len(ys))


def _fold(values: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Minimum ``(P,)`` of sampled lines ``(P, M)`` and its depth, refined by a parabola."""
    k = np.clip(np.argmin(values, axis=1), 1, len(ys) - 2)
    rows = np.arange(len(values))
    left, mid, right = values[rows, k - 1], values[rows, k], values[rows, k + 1]
    curvature = left - 2 * mid + right
    shift = np.where(curvature > 1e-15, 0.5 * (left - right) / np.maximum(curvature, 1e-15), 0.0)
    shift = np.clip(shift, -1, 1)
    step = ys[1] - ys[0]
    return mid - 0.25 * (left - right) * shift, ys[k] + shift * step


def _terms(design: Design, xz: np.ndarray, inside: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``(P, 1 + C)``: the union minimum and each cut's negated value at depth ``y``."""
    points = np.stack([xz[:, 0], y, xz[:, 1]], axis=1)
    return np.concatenate([inside[:, None], -design.cut_values(points)], axis=1)


def silhouette(design: Design, grid: float = GRID) -> Silhouette:
    """Sample the design on a frontal grid of ``grid`` metres (see :class:`Silhouette`).

    Raises:
        PatternError: if some line along Y meets the solid twice (a sleeve in front of
            the torso, say): a two-panel pattern cannot describe that garment.
    """
    lo, hi = design.bounds
    x = np.arange(lo[0], hi[0] + grid, grid)
    z = np.arange(lo[2], hi[2] + grid, grid)
    ys = np.arange(lo[1], hi[1] + Y_STEP, Y_STEP)
    xx, zz = np.meshgrid(x, z)
    xz = np.stack([xx.ravel(), zz.ravel()], axis=1)
    values = _along_y(design, xz, ys)
    inside, fold_y = _fold(values, ys)
    front_y, back_y, _ = _crossings(values, ys)
    region = {side: _terms(design, xz, inside, y).max(axis=1)
              for side, y in ((-1, front_y), (1, back_y))}
    # Two separate runs of "inside" on one line = two layers in the frontal view.
    negative = values < 0
    entries = (negative[:, 1:] & ~negative[:, :-1]).sum(axis=1) + negative[:, 0]
    if ((entries > 1) & ((region[-1] < 0) | (region[1] < 0))).any():
        raise PatternError("garment parts overlap in the frontal view (two layers along Y)")
    if (negative[:, 0] | negative[:, -1]).any():
        raise PatternError("the design reaches the depth bounds of its box")
    shape = xx.shape
    return Silhouette(x=x, z=z, ys=ys, inside=inside.reshape(shape),
                      fold_y=fold_y.reshape(shape), front_y=front_y.reshape(shape),
                      back_y=back_y.reshape(shape),
                      region={side: r.reshape(shape) for side, r in region.items()})


def _crossings(values: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Depths ``(P,)`` where sampled lines ``(P, M)`` first enter the solid from the front
    and from the back (linear interpolation; the fold depth where a line misses the
    solid), and the fold depth ``(P,)``."""
    _, fold_y = _fold(values, ys)
    negative = values < 0
    hits = negative.any(axis=1)
    rows = np.flatnonzero(hits)
    result = []
    for sign in (-1, 1):
        y = fold_y.copy()
        order = negative[rows] if sign < 0 else negative[rows][:, ::-1]
        first = np.argmax(order, axis=1)  # first inside sample seen from this side
        k = first if sign < 0 else len(ys) - 1 - first
        previous = np.clip(k + sign, 0, len(ys) - 1)  # the outside sample before it
        v_in, v_out = values[rows, k], values[rows, previous]
        denominator = np.where(v_out != v_in, v_out - v_in, 1.0)
        t = np.clip(np.where(v_out != v_in, v_out / denominator, 0.0), 0, 1)
        y[rows] = ys[previous] + t * (ys[k] - ys[previous])
        result.append(y)
    return result[0], result[1], fold_y


def region_terms(design: Design, sil: Silhouette, xz: np.ndarray, side: int) -> np.ndarray:
    """``(P, 1 + C)`` at points ``xz (P, 2)`` anywhere (not only on the grid): the terms
    whose maximum is panel ``side``'s region field, the union minimum along Y and each
    cut's negated value where that panel's surface is. The largest says what bounds Ω
    there: 0 the solid (a seam), ``k`` cut ``k − 1`` (an opening)."""
    values = _along_y(design, xz, sil.ys)
    inside, _ = _fold(values, sil.ys)
    front_y, back_y, _ = _crossings(values, sil.ys)
    return _terms(design, xz, inside, front_y if side < 0 else back_y)


def lift_on_grid(sil: Silhouette, xz: np.ndarray, side: np.ndarray) -> np.ndarray:
    """Place pattern points on the design's surface: ``(P, 3)``, by bilinear
    interpolation of the silhouette's depth maps (no field evaluation; accurate enough
    for a start that :mod:`.mesher` relaxes).

    ``side`` ``(P,)`` is −1 (front panel: where the surface is first met coming from
    −Y), +1 (back panel) or 0 (seam: the fold, where the solid is thinnest along Y).
    """
    from scipy.ndimage import map_coordinates

    rows = (xz[:, 1] - sil.z[0]) / (sil.z[1] - sil.z[0])
    cols = (xz[:, 0] - sil.x[0]) / (sil.x[1] - sil.x[0])
    y = np.empty(len(xz))
    for value, grid in ((-1, sil.front_y), (1, sil.back_y), (0, sil.fold_y)):
        mine = side == value
        y[mine] = map_coordinates(grid, [rows[mine], cols[mine]], order=1, mode="nearest")
    return np.stack([xz[:, 0], y, xz[:, 1]], axis=1)


def surface_area(sil: Silhouette) -> tuple[float, dict[int, float]]:
    """Approximate area (m²) of the kept garment surface: both panels over their Ω, each
    cell's area scaled by its slope (capped at 4: the folds are nearly vertical); and
    each panel's flat (pattern) area."""
    total, flat = 0.0, {}
    for side, y in ((-1, sil.front_y), (1, sil.back_y)):
        inside = sil.region[side] < 0
        step = float(sil.x[1] - sil.x[0])
        gz, gx = np.gradient(y, step)
        stretch = np.minimum(np.sqrt(1 + gx**2 + gz**2), 4.0)
        total += float(stretch[inside].sum()) * step**2
        flat[side] = float(inside.sum()) * step**2
    return total, flat
