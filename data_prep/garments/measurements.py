"""Body measurements the garments are sized from: cross-sections at every height.

The body's vertices are split into parts with the 24 joints: an arm vertex is much
closer to its arm's bone chain (shoulder → elbow → wrist → hand) than to the spine or a
leg; a head vertex is a non-arm vertex above the neck joint; everything else is the
*trunk* (torso and legs). Then, in 1 cm slabs:

* the trunk's section (centre, half-width, front and back depth, and the superellipse
  of least area that holds every slab vertex) from the feet to the shoulders: above
  the crotch it is the torso, below it both legs together (what a skirt must clear);
* each leg's section below the crotch (trousers);
* each arm's radius along its bone chain (sleeves);
* the shoulder line (the highest trunk point across X), the neck radius, the crotch
  height (where the two legs' sections separate) and the armpits.

All lengths in metres, Z up, the body facing −Y.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from data_prep.garments.body_frame import BodyFrame
from data_prep.garments.shapes import Sections

TRUNK, HEAD, ARM_L, ARM_R = 0, 1, 2, 3
SLAB = 0.01  # metres: the height resolution of the sections
EXPONENTS = np.array([2.0, 2.5, 3.0, 4.0, 6.0])


@dataclasses.dataclass
class Limb:
    """An arm: bone-chain polyline ``axis (M, 3)`` with arc length ``axis_t (M,)`` and the
    radius ``radius (K,)`` of the arm at arc lengths ``t (K,)`` (metres)."""

    axis: np.ndarray
    axis_t: np.ndarray
    t: np.ndarray
    radius: np.ndarray

    def point(self, t: float | np.ndarray) -> np.ndarray:
        """Point(s) on the axis at arc length ``t``."""
        t = np.asarray(t, dtype=np.float64)
        return np.stack([np.interp(t, self.axis_t, self.axis[:, k]) for k in range(3)], axis=-1)

    def direction(self, t: float) -> np.ndarray:
        """Unit axis direction at arc length ``t``."""
        i = int(np.clip(np.searchsorted(self.axis_t, t, side="right") - 1, 0, len(self.axis) - 2))
        d = self.axis[i + 1] - self.axis[i]
        return d / np.linalg.norm(d)

    def radius_at(self, t: float | np.ndarray) -> np.ndarray:
        return np.interp(t, self.t, self.radius)

    @property
    def length(self) -> float:
        """Shoulder-to-wrist arc length (the sleeve-length unit)."""
        return float(self.axis_t[2])


@dataclasses.dataclass
class BodyMeasurements:
    """What :func:`measure_body` found; see the module docstring."""

    labels: np.ndarray  # (N_b,) TRUNK / HEAD / ARM_L / ARM_R
    trunk: Sections
    legs: dict[str, Sections]
    arms: dict[str, Limb]
    shoulder_x: np.ndarray  # (S,) X positions of the shoulder line
    shoulder_z: np.ndarray  # (S,) highest trunk point at each X
    z_floor: float
    z_crotch: float
    z_hip: float
    z_waist: float
    z_chest: float
    z_shoulder: float
    z_neck: float
    z_knee: float
    z_ankle: float
    neck_center: np.ndarray  # (2,) x, y of the neck axis
    neck_radius: float  # half-width of the neck in X
    armpits: dict[str, np.ndarray]  # side -> (3,) lowest point where the arm meets the trunk
    center_y: float  # the body's middle depth (the frontal plane of the sewing pattern)
    height: float


def _segment_distance(points: np.ndarray, chain: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance ``(P,)`` from points to a polyline ``(M, 3)`` and the arc length ``(P,)``
    of the closest point."""
    best = np.full(len(points), np.inf)
    arc = np.zeros(len(points))
    start_t = 0.0
    for i in range(len(chain) - 1):
        segment = chain[i + 1] - chain[i]
        length = float(np.linalg.norm(segment))
        t = np.clip((points - chain[i]) @ segment / max(length**2, 1e-12), 0.0, 1.0)
        d = np.linalg.norm(points - (chain[i] + t[:, None] * segment), axis=1)
        closer = d < best
        best[closer] = d[closer]
        arc[closer] = start_t + t[closer] * length
        start_t += length
    return best, arc


def _label(body: BodyFrame) -> np.ndarray:
    v, j = body.vertices, body.joint
    spine = np.stack([j("pelvis"), j("spine1"), j("spine2"), j("spine3"), j("neck"), j("head")])
    d_spine, _ = _segment_distance(v, spine)
    d_legs = np.minimum(*[_segment_distance(v, np.stack(
        [j("pelvis"), j(f"{s}_hip"), j(f"{s}_knee"), j(f"{s}_ankle"), j(f"{s}_foot")]))[0]
        for s in ("L", "R")])
    labels = np.full(len(v), TRUNK)
    for side, label in (("L", ARM_L), ("R", ARM_R)):
        hand = j(f"{side}_hand")
        chain = np.stack([j(f"{side}_shoulder"), j(f"{side}_elbow"), j(f"{side}_wrist"), hand,
                          hand + 0.8 * (hand - j(f"{side}_wrist"))])
        d_arm, arc = _segment_distance(v, chain)
        # Thin limb vs thick torso: an arm vertex is much nearer its own bones. Points
        # level with the shoulder joint or inside it (arc = 0) belong to the trunk.
        is_arm = (d_arm < 0.6 * np.minimum(d_spine, d_legs)) & (arc > 0.0)
        labels[is_arm] = label
    labels[(labels == TRUNK) & (v[:, 2] > j("neck")[2])] = HEAD
    return labels


def _moving_average(values: np.ndarray, half: int) -> np.ndarray:
    """Mean over a window of ``2 half + 1`` samples (the ends repeated)."""
    padded = np.pad(values, half, mode="edge")
    return np.convolve(padded, np.ones(2 * half + 1) / (2 * half + 1), mode="valid")


def _moving_max(values: np.ndarray, half: int) -> np.ndarray:
    """Maximum over a window of ``2 half + 1`` samples: averaging this never drops below
    the original values (each window mean is over values >= the centre's)."""
    padded = np.pad(values, half, mode="edge")
    return np.max(np.stack([padded[i: i + len(values)] for i in range(2 * half + 1)]), axis=0)


def _sections(points: np.ndarray, z0: float, count: int) -> Sections:
    """Sections of a point set in ``count`` slabs of :data:`SLAB` from ``z0``; empty
    slabs are filled by interpolation, every slab also sees its neighbours (so a
    section holds the body between two sample heights)."""
    index = np.clip(((points[:, 2] - z0) / SLAB).astype(int), 0, count - 1)
    lo = np.full((count, 2), np.inf)
    hi = np.full((count, 2), -np.inf)
    for shift in (-1, 0, 1):
        k = np.clip(index + shift, 0, count - 1)
        np.minimum.at(lo, k, points[:, :2])
        np.maximum.at(hi, k, points[:, :2])
    z = z0 + SLAB * (np.arange(count) + 0.5)
    filled = np.isfinite(lo[:, 0])
    if filled.sum() < 2:
        raise ValueError("too few body vertices to measure a section profile")
    for arr in (lo, hi):
        for c in range(2):
            arr[:, c] = np.interp(z, z[filled], arr[filled, c])
    cx = (lo[:, 0] + hi[:, 0]) / 2
    cy = (lo[:, 1] + hi[:, 1]) / 2
    a = np.maximum((hi[:, 0] - lo[:, 0]) / 2, 0.01)
    bf = np.maximum(cy - lo[:, 1], 0.01)
    bb = np.maximum(hi[:, 1] - cy, 0.01)
    # The superellipse exponent of least area s² A(p) (s: the scale that makes it hold
    # every point of the slab and its neighbours, A(p) = 4 Γ(1 + 1/p)² / Γ(1 + 2/p)):
    # an ellipse for round sections, boxier only where that is tighter. Then p is
    # smoothed along Z (a jumpy exponent makes a bumpy surface) and the scale recomputed
    # for the smoothed p, so every section still holds its points.
    from scipy.special import gamma

    dx = np.abs(points[:, 0] - cx[index]) / a[index]
    front = points[:, 1] < cy[index]
    dy = np.abs(points[:, 1] - cy[index]) / np.where(front, bf[index], bb[index])
    big = np.maximum(np.maximum(dx, dy), 1e-12)
    small = np.minimum(dx, dy) / big

    def worst_rho(exponent: np.ndarray) -> np.ndarray:
        rho = big * (1.0 + small**exponent) ** (1.0 / exponent)
        worst = np.ones(count)
        for shift in (-1, 0, 1):
            np.maximum.at(worst, np.clip(index + shift, 0, count - 1), rho)
        return worst

    best_area = np.full(count, np.inf)
    p = np.full(count, 2.0)
    for exponent in EXPONENTS:
        area = worst_rho(np.full(len(points), exponent)) ** 2 * 4 * gamma(
            1 + 1 / exponent) ** 2 / gamma(1 + 2 / exponent)
        better = area < best_area - 1e-12
        best_area = np.where(better, area, best_area)
        p = np.where(better, exponent, p)
    p = _moving_average(p, 4)
    scale = _moving_average(_moving_max(worst_rho(p[index]), 2), 2)
    a, bf, bb = (_moving_average(_moving_max(v * scale, 2), 2) for v in (a, bf, bb))
    cx, cy = _moving_average(cx, 2), _moving_average(cy, 2)
    return Sections(z=z, cx=cx, cy=cy, a=a, bf=bf, bb=bb, p=p)


def measure_body(body: BodyFrame) -> BodyMeasurements:
    """Measure a rest body (see the module docstring). Takes ~20 ms for Anny."""
    v, j = body.vertices, body.joint
    labels = _label(body)
    trunk_points = v[labels == TRUNK]
    z_floor = float(v[:, 2].min())
    z_top_trunk = float(trunk_points[:, 2].max())
    count = int(np.ceil((z_top_trunk - z_floor) / SLAB)) + 1
    trunk = _sections(trunk_points, z_floor, count)

    # Crotch: the highest slab below the hips with no trunk vertex near the midline.
    mid_x = float((j("L_hip")[0] + j("R_hip")[0]) / 2)
    z_hip = float((j("L_hip")[2] + j("R_hip")[2]) / 2)
    gap = 0.004
    slab_of = ((trunk_points[:, 2] - z_floor) / SLAB).astype(int)
    near_mid = np.zeros(count, dtype=bool)
    near_mid[slab_of[np.abs(trunk_points[:, 0] - mid_x) < gap]] = True
    knee_z = float(min(j("L_knee")[2], j("R_knee")[2]))
    candidates = [k for k in range(count) if knee_z < trunk.z[k] < z_hip and not near_mid[k]]
    z_crotch = float(trunk.z[max(candidates)]) if candidates else float((z_hip + knee_z) / 2)

    legs = {}
    for side, sign in (("L", 1.0), ("R", -1.0)):
        mine = trunk_points[(np.sign(trunk_points[:, 0] - mid_x) == sign)
                            & (trunk_points[:, 2] < z_crotch + SLAB)]
        legs[side] = _sections(mine, z_floor, int(np.ceil((z_crotch - z_floor) / SLAB)) + 1)

    arms, armpits = {}, {}
    for side, label in (("L", ARM_L), ("R", ARM_R)):
        hand = j(f"{side}_hand")
        axis = np.stack([j(f"{side}_shoulder"), j(f"{side}_elbow"), j(f"{side}_wrist"), hand,
                         hand + 0.8 * (hand - j(f"{side}_wrist"))])
        axis_t = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(axis, axis=0), axis=1))])
        points = v[labels == label]
        d, arc = _segment_distance(points, axis)
        bins = int(np.ceil(axis_t[-1] / SLAB)) + 1
        k = np.clip((arc / SLAB).astype(int), 0, bins - 1)
        radius = np.full(bins, -np.inf)
        for shift in (-2, -1, 0, 1, 2):
            np.maximum.at(radius, np.clip(k + shift, 0, bins - 1), d)
        t = SLAB * (np.arange(bins) + 0.5)
        ok = np.isfinite(radius)
        radius = np.interp(t, t[ok], radius[ok])
        arms[side] = Limb(axis=axis, axis_t=axis_t, t=t, radius=radius)
        root = points[arc < 0.1]
        armpits[side] = root[np.argmin(root[:, 2])] if len(root) else j(f"{side}_shoulder")

    # Shoulder line: the highest trunk point per 1 cm of X, between the shoulder joints.
    shoulder_half = float(abs(j("L_shoulder")[0] - j("R_shoulder")[0]) / 2)
    xs = mid_x + np.arange(-shoulder_half - 0.04, shoulder_half + 0.04 + 1e-9, SLAB)
    upper = v[(labels == TRUNK) & (v[:, 2] > float(j("spine3")[2]))]
    column = np.clip(np.round((upper[:, 0] - xs[0]) / SLAB).astype(int), 0, len(xs) - 1)
    top = np.full(len(xs), -np.inf)
    for shift in (-1, 0, 1):
        np.maximum.at(top, np.clip(column + shift, 0, len(xs) - 1), upper[:, 2])
    ok = np.isfinite(top)
    # Smoothed upper envelope (±4 cm): garments drape over the trapezius and neck base
    # as one slope, without following every bump.
    top = _moving_average(_moving_max(np.interp(xs, xs[ok], top[ok]), 4), 4)

    # Neck: the head/neck vertices in the 2 cm above the neck joint (below the chin);
    # its half-width in X is what a Y-extruded neckline cut must clear.
    neck = j("neck")
    ring = v[(labels == HEAD) & (v[:, 2] < neck[2] + 0.02)]
    if len(ring) < 8:
        raise ValueError("cannot find the neck: no body vertices just above the neck joint")
    neck_center = (ring[:, :2].min(axis=0) + ring[:, :2].max(axis=0)) / 2
    neck_radius = float(np.abs(ring[:, 0] - neck_center[0]).max())

    return BodyMeasurements(
        labels=labels, trunk=trunk, legs=legs, arms=arms, shoulder_x=xs, shoulder_z=top,
        z_floor=z_floor, z_crotch=z_crotch, z_hip=z_hip,
        z_waist=float((j("spine1")[2] + j("spine2")[2]) / 2), z_chest=float(j("spine3")[2]),
        z_shoulder=float((j("L_shoulder")[2] + j("R_shoulder")[2]) / 2), z_neck=float(neck[2]),
        z_knee=knee_z, z_ankle=float(max(j("L_ankle")[2], j("R_ankle")[2])),
        neck_center=np.asarray(neck_center, dtype=np.float64), neck_radius=neck_radius,
        armpits=armpits, center_y=float(np.median(trunk.cy[trunk.z > z_crotch])),
        height=float(v[:, 2].max() - z_floor),
    )
