"""Implicit garment shapes: solids whose union is the garment's inside, and cuts.

A garment is the boundary of the union of a few smooth solids (a torso or skirt
"stack", leg stacks, sleeve tubes), trimmed by cuts (hem, waist, cuffs, neck,
armholes). Every solid is a field ``f(x)`` that is negative inside and roughly a
signed distance in metres near its surface; the union is a polynomial smooth minimum,
so junctions (armpit, crotch) get a fillet of width ``blend`` instead of a crease. A
cut ``c(x)`` keeps the part of the surface where ``c >= 0``. Cuts are planes, disks
across a limb, or regions extruded along Y (the body's front–back axis) with an
optional tilt, so that they cut both panels of the sewing pattern (:mod:`.pattern`)
along one curve each. Solids give an analytic gradient (:meth:`Design.field_and_gradient`)
for the mesher's Newton steps.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np


def smooth_min(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Polynomial smooth minimum (``<= min(a, b)``, equal to it when ``|a − b| >= k``)."""
    if k <= 0:
        return np.minimum(a, b)
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * k * 0.25


def smooth_max(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Polynomial smooth maximum (``>= max(a, b)``)."""
    return -smooth_min(-a, -b, k)


def smooth_min_grad(a: np.ndarray, ga: np.ndarray, b: np.ndarray, gb: np.ndarray,
                    k: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`smooth_min` and its gradient ``(P, 3)`` from the operands' gradients: the
    smaller operand weighs ``1 − h/2``, the other ``h/2``."""
    h = np.maximum(k - np.abs(a - b), 0.0) / k if k > 0 else np.zeros_like(a)
    value = np.minimum(a, b) - h * h * k * 0.25
    w_small = 1.0 - 0.5 * h
    a_smaller = (a <= b)[:, None]
    grad = np.where(a_smaller, w_small[:, None] * ga + (1 - w_small)[:, None] * gb,
                    w_small[:, None] * gb + (1 - w_small)[:, None] * ga)
    return value, grad


def smooth_max_grad(a: np.ndarray, ga: np.ndarray, b: np.ndarray, gb: np.ndarray,
                    k: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`smooth_max` and its gradient."""
    value, grad = smooth_min_grad(-a, -ga, -b, -gb, k)
    return -value, -grad


class UniformTable:
    """Piecewise-linear interpolation of ``values (K, C)`` sampled at ``knots (K,)``,
    resampled once onto a uniform grid so a lookup is an index computation and a
    gather (``np.interp`` searches per point: ~20× slower on 10⁵ points). Values are
    held constant beyond the ends."""

    def __init__(self, knots: np.ndarray, values: np.ndarray, step: float = 0.005) -> None:
        knots = np.asarray(knots, dtype=np.float64)
        values = np.asarray(values, dtype=np.float64).reshape(len(knots), -1)
        count = max(int(np.ceil((knots[-1] - knots[0]) / step)) + 1, 2)
        self.start = float(knots[0])
        self.step = (float(knots[-1]) - self.start) / (count - 1) if knots[-1] > knots[0] else 1.0
        grid = self.start + self.step * np.arange(count)
        self.table = np.stack([np.interp(grid, knots, values[:, c])
                               for c in range(values.shape[1])], axis=1)

        # Value and slope per cell, as rows, so one gather serves both and each profile
        # comes out as a contiguous (P,) row.
        slope = np.diff(self.table, axis=0) / self.step
        self._cells = np.ascontiguousarray(np.concatenate([self.table[:-1], slope], axis=1).T)
        self._columns = self.table.shape[1]

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """``(C, P)`` interpolated values at ``x (P,)``."""
        return self.with_slope(x, slopes=False)[0]

    def with_slope(self, x: np.ndarray, slopes: bool = True
                   ) -> tuple[np.ndarray, np.ndarray | None]:
        """``(C, P)`` values and ``(C, P)`` derivatives along ``x`` (0 beyond the ends;
        ``None`` unless asked)."""
        u = (x - self.start) / self.step
        clipped = np.clip(u, 0.0, len(self.table) - 1.000001)
        i = clipped.astype(np.int64)
        cell = np.take(self._cells, i, axis=1)
        slope = cell[self._columns:]
        value = cell[: self._columns] + (clipped - i) * self.step * slope
        if not slopes:
            return value, None
        outside = (u < 0) | (u > len(self.table) - 1)
        return value, np.where(outside, 0.0, slope)


@dataclasses.dataclass
class Sections:
    """Superelliptic sections at heights ``z`` (all ``(K,)``, metres): centre ``(cx, cy)``,
    half-width ``a``, front depth ``bf`` (−Y), back depth ``bb`` (+Y), exponent ``p``
    (2 = ellipse, larger = boxier). A body's measured sections
    (:mod:`.measurements`) and the profile of a :class:`Stack` solid."""

    z: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    a: np.ndarray
    bf: np.ndarray
    bb: np.ndarray
    p: np.ndarray

    def at(self, z: float) -> dict[str, float]:
        """The section interpolated at one height."""
        return {name: float(np.interp(z, self.z, getattr(self, name)))
                for name in ("cx", "cy", "a", "bf", "bb", "p")}

    def between(self, low: float, high: float) -> Sections:
        """The sections with ``low <= z <= high`` (at least the two nearest)."""
        keep = (self.z >= low) & (self.z <= high)
        if keep.sum() < 2:
            keep = np.argsort(np.abs(self.z - (low + high) / 2))[:2]
            keep = np.sort(keep)
        # Sections' own fields only: a Stack's caps are not per height.
        return Sections(*(getattr(self, f.name)[keep] for f in dataclasses.fields(Sections)))


@dataclasses.dataclass
class Stack(Sections):
    """A generalised cylinder along Z with superelliptic cross-sections.

    At height ``z`` the section is centred at ``(cx, cy)``, reaches ``a`` to each side in
    X, ``bf`` to the front (−Y) and ``bb`` to the back (+Y), with exponent ``p`` (2 =
    ellipse, larger = boxier): the :class:`Sections` fields, sampled at increasing ``z``
    (all ``(K,)``, metres) and held constant beyond the ends. Optional ``top`` caps the
    solid at the height ``top_z`` over ``top_x`` (a shoulder line); optional ``bottom``
    caps it from below at one height (the crotch of a pair of trousers).
    """

    top_x: np.ndarray | None = None
    top_z: np.ndarray | None = None
    bottom: float | None = None
    round_cap: float = 0.03

    def __post_init__(self) -> None:
        self._profile = UniformTable(
            self.z, np.stack([self.cx, self.cy, self.a, self.bf, self.bb, self.p], axis=1))
        self._top = (None if self.top_x is None or self.top_z is None
                     else UniformTable(self.top_x, self.top_z))

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """Field ``(P,)`` at ``points (P, 3)``: negative inside."""
        return self.value_and_gradient(points, gradient=False)[0]

    def value_and_gradient(self, points: np.ndarray, gradient: bool = True
                           ) -> tuple[np.ndarray, np.ndarray | None]:
        """Field ``(P,)`` and its analytic gradient ``(P, 3)`` (``None`` unless asked)."""
        x, y, z = points[:, 0], points[:, 1], points[:, 2]
        (cx, cy, a, bf, bb, p), slopes = self._profile.with_slope(z, slopes=gradient)
        front = y < cy
        b = np.where(front, bf, bb)
        u = (x - cx) / a
        v = (y - cy) / b
        dx, dy = np.abs(u), np.abs(v)
        # rho^p = dx^p + dy^p, computed with the larger term factored out (no overflow).
        big = np.maximum(np.maximum(dx, dy), 1e-12)
        small = np.minimum(dx, dy) / big
        ratio = np.exp(p * np.log(np.maximum(small, 1e-300)))  # small^p
        rho = big * np.exp(np.log1p(ratio) / p)
        # Scale by the local size: exact distance for a circle, close to it for an ellipse
        # (the mean depth, not the side's: the field stays continuous across y = cy).
        depth = 0.5 * (bf + bb)
        size = np.minimum(a, depth)
        field = (rho - 1.0) * size
        grad = None
        if gradient:
            # d rho / d u = sign(u) |u|^(p-1) rho^(1-p), written with dx/rho to stay finite.
            du = np.sign(u) * np.exp((p - 1) * np.log(np.maximum(dx / rho, 1e-300)))
            dv = np.sign(v) * np.exp((p - 1) * np.log(np.maximum(dy / rho, 1e-300)))
            assert slopes is not None
            dcx, dcy, da, dbf, dbb, dp = slopes
            db = np.where(front, dbf, dbb)
            du_dz = -dcx / a - u * da / a
            dv_dz = -dcy / b - v * db / b
            dsize_dz = np.where(a <= depth, da, 0.5 * (dbf + dbb))
            # d rho / d p = rho (r ln(s) / ((1 + r) p) − ln(1 + r) / p²), s = small, r = s^p.
            drho_dp = rho * (ratio * np.log(np.maximum(small, 1e-300)) / ((1 + ratio) * p)
                             - np.log1p(ratio) / (p * p))
            grad = np.stack([size * du / a, size * dv / b,
                             size * (du * du_dz + dv * dv_dz + drho_dp * dp)
                             + (rho - 1.0) * dsize_dz], axis=1)
        if self._top is not None:
            top, top_slope = self._top.with_slope(x, slopes=gradient)
            cap = z - top[0]
            if gradient:
                assert top_slope is not None
                cap_grad = np.stack([-top_slope[0], np.zeros_like(z), np.ones_like(z)], axis=1)
                field, grad = smooth_max_grad(field, grad, cap, cap_grad, self.round_cap)
            else:
                field = smooth_max(field, cap, self.round_cap)
        if self.bottom is not None:
            floor = self.bottom - z
            if gradient:
                floor_grad = np.zeros_like(points)
                floor_grad[:, 2] = -1.0
                field, grad = smooth_max_grad(field, grad, floor, floor_grad, self.round_cap)
            else:
                field = smooth_max(field, floor, self.round_cap)
        return field, grad


@dataclasses.dataclass
class Tube:
    """A tube around a polyline axis (a sleeve along the arm's bones): ``axis (M, 3)``,
    and its radius ``radius (K,)`` at arc lengths ``t (K,)`` along the axis (metres;
    piecewise linear, held beyond the ends).

    Points farther than ``reach`` from the tube's bounding box get the box distance
    instead of the exact value: it is a positive lower bound, so the zero set of any
    union whose blend is below ``reach`` is unchanged, and far points cost nothing.
    """

    axis: np.ndarray
    t: np.ndarray
    radius: np.ndarray
    reach: float = 0.08

    def __post_init__(self) -> None:
        grow = float(np.max(self.radius)) + self.reach
        self._box = (self.axis.min(axis=0) - grow, self.axis.max(axis=0) + grow)
        self._radius = UniformTable(self.t, self.radius)
        lengths = np.linalg.norm(np.diff(self.axis, axis=0), axis=1)
        self._start_t = np.concatenate([[0.0], np.cumsum(lengths)])

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """Field ``(P,)`` at ``points (P, 3)``: negative inside."""
        return self.value_and_gradient(points, gradient=False)[0]

    def value_and_gradient(self, points: np.ndarray, gradient: bool = True
                           ) -> tuple[np.ndarray, np.ndarray | None]:
        """Field ``(P,)`` and gradient ``(P, 3)`` (``None`` unless asked)."""
        gap = np.maximum(self._box[0] - points, 0) - np.maximum(points - self._box[1], 0)
        gap_length = np.sqrt((gap * gap).sum(axis=1))
        result = gap_length + self.reach
        grad = -gap / np.maximum(gap_length, 1e-12)[:, None] if gradient else None
        near = np.flatnonzero(gap_length == 0)
        p = points[near]
        # The closest point on the polyline: per segment, keep the nearest.
        best = np.full(len(p), np.inf)
        arc = np.zeros(len(p))
        offset_best = np.zeros((len(p), 3))
        direction = np.zeros((len(p), 3))
        inside = np.zeros(len(p), dtype=bool)
        for i in range(len(self.axis) - 1):
            start, segment = self.axis[i], self.axis[i + 1] - self.axis[i]
            length2 = float(segment @ segment)
            relative = p - start
            raw = relative @ segment / length2
            u = np.clip(raw, 0.0, 1.0)
            offset = relative - u[:, None] * segment
            distance2 = np.einsum("ij,ij->i", offset, offset)
            better = distance2 < best
            best = np.where(better, distance2, best)
            arc = np.where(better, self._start_t[i] + u * np.sqrt(length2), arc)
            offset_best[better] = offset[better]
            direction[better] = segment / np.sqrt(length2)
            inside = np.where(better, (raw > 0) & (raw < 1), inside)
        distance = np.sqrt(best)
        radius, slope = self._radius.with_slope(arc, slopes=gradient)
        result[near] = distance - radius[0]
        if gradient:
            assert grad is not None and slope is not None
            unit = offset_best / np.maximum(distance, 1e-12)[:, None]
            # The radius varies with the arc length, which moves with the point only
            # while its projection is inside a segment.
            grad[near] = unit - np.where(inside, slope[0], 0.0)[:, None] * direction
        return result, grad


@dataclasses.dataclass
class PlaneCut:
    """Keep the side ``(x − point) · normal >= 0`` (hem, waist, cuff); unit ``normal``."""

    name: str
    point: np.ndarray
    normal: np.ndarray

    def __call__(self, points: np.ndarray) -> np.ndarray:
        return (points - self.point) @ self.normal


@dataclasses.dataclass
class DiskCut:
    """A plane cut limited to a cylinder: remove the points beyond the plane through
    ``point`` (on the side opposite to the unit ``normal``) that are within ``radius``
    of the line through ``point`` along ``normal``. A cuff cut that leaves the torso
    alone even where the plane would cross it (arms hanging in an A-pose)."""

    name: str
    point: np.ndarray
    normal: np.ndarray
    radius: float

    def __call__(self, points: np.ndarray) -> np.ndarray:
        relative = points - self.point
        along = relative @ self.normal
        across = np.linalg.norm(relative - along[:, None] * self.normal, axis=1)
        # Removed where both "beyond the plane" (-along > 0) and "in the cylinder" hold.
        return -np.minimum(-along, self.radius - across)


@dataclasses.dataclass
class EllipseCut:
    """Remove a Y-extruded superellipse ``|dx/rx|^p + |dz/rz|^p < 1`` (neck, armhole),
    optionally turned by ``angle`` in the (X, Z) plane.

    ``tilt`` lowers the cut towards the front: at depth ``y`` the ellipse is centred at
    ``cz + tilt · (y − cy)``, so with ``tilt > 0`` a neckline is deeper in front
    (``y < cy``) than at the back.
    """

    name: str
    cx: float
    cz: float
    rx: float
    rz: float
    p: float = 2.0
    cy: float = 0.0
    tilt: float = 0.0
    angle: float = 0.0  # radians: the ``rx`` axis turned from +X towards +Z

    def __call__(self, points: np.ndarray) -> np.ndarray:
        u = points[:, 0] - self.cx
        w = points[:, 2] - (self.cz + self.tilt * (points[:, 1] - self.cy))
        if self.angle:
            c, s = np.cos(self.angle), np.sin(self.angle)
            u, w = c * u + s * w, -s * u + c * w
        dx = np.abs(u) / self.rx
        dz = np.abs(w) / self.rz
        big = np.maximum(np.maximum(dx, dz), 1e-12)
        rho = big * ((dx / big) ** self.p + (dz / big) ** self.p) ** (1.0 / self.p)
        return (rho - 1.0) * min(self.rx, self.rz)


@dataclasses.dataclass
class VCut:
    """Remove the region above a V: ``z > apex_z + slope · |x − cx|`` (a V-neck);
    ``tilt`` as in :class:`EllipseCut`."""

    name: str
    cx: float
    apex_z: float
    slope: float
    cy: float = 0.0
    tilt: float = 0.0

    def __call__(self, points: np.ndarray) -> np.ndarray:
        apex = self.apex_z + self.tilt * (points[:, 1] - self.cy)
        return (apex + self.slope * np.abs(points[:, 0] - self.cx) - points[:, 2]) / np.sqrt(
            1.0 + self.slope**2)


@dataclasses.dataclass
class UnionCut:
    """Remove what any of ``parts`` removes (a V-neck: a V in front, round at the back),
    with the corners where their rims meet rounded over ``blend`` metres (a sharp
    corner in an opening's loop makes slivers)."""

    name: str
    parts: tuple
    blend: float = 0.015

    def __call__(self, points: np.ndarray) -> np.ndarray:
        value = self.parts[0](points)
        for part in self.parts[1:]:
            value = smooth_min(value, part(points), self.blend)
        return value


@dataclasses.dataclass
class Group:
    """Solids united among themselves with their own (small) blend, then as one solid
    with the rest: two trouser legs, which the design's wide blend must not bridge where
    they pass close to each other, but whose crease at the top of the inseam is still
    rounded off a little."""

    parts: tuple
    blend: float = 0.0

    def __call__(self, points: np.ndarray) -> np.ndarray:
        return self.value_and_gradient(points, gradient=False)[0]

    def value_and_gradient(self, points: np.ndarray, gradient: bool = True
                           ) -> tuple[np.ndarray, np.ndarray | None]:
        value, grad = self.parts[0].value_and_gradient(points, gradient)
        for part in self.parts[1:]:
            other, other_grad = part.value_and_gradient(points, gradient)
            if gradient:
                value, grad = smooth_min_grad(value, grad, other, other_grad, self.blend)
            else:
                value = smooth_min(value, other, self.blend)
        return value, grad


Solid = Stack | Tube | Group
Cut = PlaneCut | DiskCut | EllipseCut | VCut | UnionCut


@dataclasses.dataclass
class Design:
    """A garment as an implicit surface: ``solids`` united with a smooth minimum of
    radius ``blend`` (metres), trimmed by ``cuts``; ``bounds`` ``(2, 3)`` is a box that
    holds the kept part of the surface."""

    solids: Sequence[Solid]
    cuts: Sequence[Cut]
    bounds: np.ndarray
    blend: float = 0.04

    def __post_init__(self) -> None:
        for solid in self.solids:
            if isinstance(solid, Tube) and solid.reach <= self.blend:
                raise ValueError("a tube's reach must exceed the design's blend")

    def field(self, points: np.ndarray) -> np.ndarray:
        """``(P,)`` union field: negative inside the garment's solid."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        value = self.solids[0](points)
        for solid in self.solids[1:]:
            value = smooth_min(value, solid(points), self.blend)
        return value

    def field_and_gradient(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(P,)`` union field and its analytic gradient ``(P, 3)``."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        value, grad = self.solids[0].value_and_gradient(points)
        for solid in self.solids[1:]:
            other, other_grad = solid.value_and_gradient(points)
            value, grad = smooth_min_grad(value, grad, other, other_grad, self.blend)
        return value, grad

    def cut_values(self, points: np.ndarray) -> np.ndarray:
        """``(P, C)``: each cut's value (the surface is kept where all are ``>= 0``)."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return np.stack([cut(points) for cut in self.cuts], axis=1)


def gradient(function: object, points: np.ndarray, step: float = 1e-4,
             value: np.ndarray | None = None) -> np.ndarray:
    """``(P, 3)`` finite-difference gradient of a field ``(P, 3) -> (P,)``: forward
    differences when the ``value (P,)`` at ``points`` is given, central otherwise."""
    offsets = np.eye(3) * step
    if value is not None:
        stacked = np.concatenate([points + o for o in offsets])
        values = function(stacked).reshape(3, len(points))  # type: ignore[operator]
        return (values - value[None, :]).T / step
    stacked = np.concatenate([points + o for o in offsets] + [points - o for o in offsets])
    values = function(stacked).reshape(6, len(points))  # type: ignore[operator]
    return (values[:3] - values[3:]).T / (2 * step)
