"""Garment parts sized from body measurements: the solids and cuts that the garment
types (``skirt.py`` … ``jumpsuit.py``) assemble into a :class:`~.shapes.Design`.

Fitting rule, everywhere: a part is the body's measured section (or limb radius) plus
the style's looseness, so at zero looseness it would touch the body; the mesher then
keeps every vertex at least the clearance (1 cm) away. Skirts widen monotonically
below the hips (they hang over both legs, never between them) and flare linearly.
All lengths in metres, Z up, the body facing −Y.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from data_prep.garments.errors import PatternError
from data_prep.garments.measurements import TRUNK, BodyMeasurements
from data_prep.garments.shapes import (
    Cut,
    DiskCut,
    EllipseCut,
    Group,
    PlaneCut,
    Sections,
    Solid,
    Stack,
    Tube,
    UnionCut,
    VCut,
)

if TYPE_CHECKING:
    from data_prep.garments.style import Style

CLEARANCE = 0.01  # metres: least distance of any garment vertex from the body
MIN_STRAP = 0.025  # metres: narrowest shoulder strap of a sleeveless garment
MAX_FLARE = 0.45  # metres: most a skirt's hem reaches beyond the body's hips
SKIRT_EXPONENT = 2.5  # superellipse exponent a skirt's section turns to below the hips
NECKLINES = ("round", "v", "boat", "square")  # the shapes :func:`neck_cut` makes


def _cumulative_max_down(values: np.ndarray, z: np.ndarray, below: float) -> np.ndarray:
    """For heights under ``below``, the maximum of ``values`` from ``below`` down to
    there (``z`` ascending), so a skirt never narrows between the legs."""
    out = values.copy()
    idx = np.flatnonzero(z < below)[::-1]
    running = np.interp(below, z, values)
    for i in idx:
        running = max(running, values[i])
        out[i] = running
    return out


def trunk_stack(m: BodyMeasurements, z_low: float, z_high: float, looseness: float, *,
                skirt_from: float | None = None, flare: float = 0.0, cap: bool = True,
                bottom: float | None = None, vertices: np.ndarray | None = None) -> Stack:
    """The torso (and skirt) solid between ``z_low`` and ``z_high``.

    Args:
        m: body measurements.
        z_low, z_high: height range to sample (the solid continues beyond, constant).
        looseness: added to the half-width and both depths of every section.
        skirt_from: below this height the section never narrows (a skirt or a dress
            hangs over both legs), turns elliptical and grows by ``flare`` metres per
            metre of drop (at most :data:`MAX_FLARE`). Needs the body's ``vertices``
            ``(N_b, 3)``, so the rounder section still holds the legs.
        cap: close the top along the shoulder line (shirts, tops, dresses).
        bottom: close the bottom at this height (trousers' crotch).
    """
    sections: Sections = m.trunk.between(z_low - 0.05, z_high + 0.05)
    z = sections.z
    a, bf, bb, p = sections.a, sections.bf, sections.bb, sections.p.copy()
    cx, cy = sections.cx.copy(), sections.cy.copy()
    if skirt_from is not None:
        if vertices is None:
            raise ValueError("a skirt section needs the body's vertices")
        # Re-centre on the hips, measure each section's reach from there, and make the
        # reach never shrink going down (the skirt hangs over both legs).
        at = sections.at(skirt_from)
        below = z < skirt_from
        a = np.where(below, np.maximum(np.abs(cx - a - at["cx"]), np.abs(cx + a - at["cx"])), a)
        bf = np.where(below, at["cy"] - (cy - bf), bf)
        bb = np.where(below, (cy + bb) - at["cy"], bb)
        cx = np.where(below, at["cx"], cx)
        cy = np.where(below, at["cy"], cy)
        # Round off (two legs side by side make a boxy section) within 15 cm of drop,
        # then scale each section up until it holds the body there again.
        drop = np.clip(skirt_from - z, 0.0, None)
        p = np.where(below, p + (SKIRT_EXPONENT - p) * np.clip(drop / 0.15, 0.0, 1.0), p)
        a, bf, bb = (_cumulative_max_down(v, z, skirt_from) for v in (a, bf, bb))
        scale = _containing_scale(vertices[(m.labels == TRUNK) & (vertices[:, 2] < skirt_from)],
                                  z, cx, cy, a, bf, bb, p)
        scale = _cumulative_max_down(np.where(below, scale, 1.0), z, skirt_from)
        widen = np.minimum(flare * drop, MAX_FLARE)
        a, bf, bb = (v * scale + widen for v in (a, bf, bb))
    top_x = top_z = None
    if cap:
        top_x = m.shoulder_x
        top_z = m.shoulder_z + looseness
    return Stack(z=z, cx=cx, cy=cy, a=a + looseness, bf=bf + looseness, bb=bb + looseness,
                 p=p, top_x=top_x, top_z=top_z, bottom=bottom)


def shirt_torso(m: BodyMeasurements, body_vertices: np.ndarray, length: float,
                looseness: float) -> tuple[float, Stack]:
    """The hem height and torso solid of a top-half garment (T-shirt, top): ``length``
    0 puts the hem at the natural waist (cropped), 1 at 12 cm below the crotch (tunic);
    a hem below the hips hangs like a skirt (``body_vertices (N_b, 3)``)."""
    z_hem = m.z_waist - length * (m.z_waist - (m.z_crotch - 0.12))
    torso = trunk_stack(m, z_hem - 0.1, float(m.shoulder_z.max()) + 0.1, looseness,
                        skirt_from=m.z_hip if z_hem < m.z_hip else None,
                        vertices=body_vertices)
    return z_hem, torso


def _containing_scale(points: np.ndarray, z: np.ndarray, cx: np.ndarray, cy: np.ndarray,
                      a: np.ndarray, bf: np.ndarray, bb: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``(K,)`` factor by which each section (at heights ``z``, 1 cm apart) must grow to
    hold the ``points`` within a slab of it (1 where it already does)."""
    k = np.clip(np.round((points[:, 2] - z[0]) / (z[1] - z[0])).astype(int), 0, len(z) - 1)
    dx = np.abs(points[:, 0] - cx[k]) / a[k]
    dy = np.abs(points[:, 1] - cy[k]) / np.where(points[:, 1] < cy[k], bf[k], bb[k])
    rho = (dx ** p[k] + dy ** p[k]) ** (1.0 / p[k])
    scale = np.ones(len(z))
    for shift in (-1, 0, 1):
        np.maximum.at(scale, np.clip(k + shift, 0, len(z) - 1), rho)
    return scale


LEG_GAP = 0.03  # metres: least gap between the two trouser legs where they are separate
# Blend between the two legs: rounds the crease at the top of the inseam; it only
# bridges gaps under half its size, well below LEG_GAP.
LEG_BLEND = 0.02
# Blend between the hips and the legs (trousers, jumpsuits): wide, so the seat runs
# smoothly into the thighs; the legs are one hard union, so it never bridges the gap
# between them.
SEAT_BLEND = 0.07


def leg_stacks(m: BodyMeasurements, looseness: float, flare: float, flare_from: float,
               top: float) -> tuple[list[Stack], float]:
    """Both trouser legs: each leg's sections plus ``looseness``, widening by ``flare``
    metres per metre below ``flare_from``, capped at ``top`` (inside the hips).

    The widening goes outward first: the inner edges only move in while the legs stay
    :data:`LEG_GAP` apart, so wide legs never merge in the frontal view.

    Returns:
        the two stacks (left, right) and the height below which the legs are separate
        (a hem must lie below it, or the two leg openings would be one).
    """
    left, right = m.legs["L"], m.legs["R"]
    z = left.z
    if not np.array_equal(z, right.z):
        raise ValueError("left and right leg sections must share their heights")
    extra = flare * np.clip(flare_from - z, 0.0, None)
    inner = {"L": left.cx - left.a - looseness, "R": right.cx + right.a + looseness}
    room = np.clip((inner["L"] - inner["R"] - 1.2 * LEG_GAP) / 2, 0.0, None)
    inward = np.minimum(extra / 2, room)
    outward = extra - inward
    stacks = []
    for sign, sec in ((1.0, left), (-1.0, right)):
        a = sec.a + looseness + extra / 2
        cx = sec.cx + sign * (outward - inward) / 2
        grow = looseness + extra / 2
        width = np.array([m.shoulder_x[0], m.shoulder_x[-1]])
        stacks.append(Stack(z=z, cx=cx, cy=sec.cy, a=a, bf=sec.bf + grow, bb=sec.bb + grow,
                            p=np.minimum(sec.p, 3.0), top_x=width, top_z=np.full(2, top)))
    gap = (stacks[0].cx - stacks[0].a) - (stacks[1].cx + stacks[1].a)
    merged = np.flatnonzero((gap < LEG_GAP) & (z >= m.z_ankle))
    # Going up from the ankles, the legs are apart until the first height where they meet.
    z_apart = float(z[merged.min()]) if len(merged) else float(z[-1])
    return stacks, z_apart


def sleeve(m: BodyMeasurements, side: str, length: float, looseness: float,
           flare: float) -> tuple[Tube, DiskCut]:
    """A sleeve tube along the arm and its cuff cut.

    Args:
        length: fraction of the shoulder-to-wrist length covered (``> 0``).
        looseness: gap to the arm; ``flare``: extra radius per metre along the arm.
    """
    arm = m.arms[side]
    t_cut = length * arm.length
    # The radius sampled every 2 cm, so the tube follows the arm (deltoid, elbow, wrist),
    # held constant past the cuff; the axis is the bone chain up to 6 cm past the cuff.
    t = np.arange(0.0, t_cut + 0.06, 0.02)
    # The measured radius near the shoulder joint includes the top of the shoulder
    # (which the torso's cap already covers): limit it to 1.2 × the radius 8 cm out.
    arm_radius = np.minimum(arm.radius_at(np.minimum(t, t_cut)),
                            np.where(t < 0.08, 1.2 * float(arm.radius_at(0.08)), np.inf))
    radius = arm_radius + looseness + flare * np.minimum(t, t_cut)
    cut = DiskCut(f"cuff_{side}", point=arm.point(t_cut), normal=-arm.direction(t_cut),
                  radius=float(radius[-1]) + 0.04)
    bones = arm.axis_t[(arm.axis_t > 0) & (arm.axis_t < t_cut + 0.06)]
    axis = arm.point(np.concatenate([[0.0], bones, [t_cut + 0.06]]))
    return Tube(axis=axis, t=t, radius=radius), cut


def neck_cut(m: BodyMeasurements, torso: Stack, *, front_depth: float, back_depth: float,
             width: float, shape: str, max_half: float = np.inf) -> tuple[Cut, float]:
    """The neckline: removes a Y-extruded region around the neck, ``front_depth``
    below the top of the garment in front and ``back_depth`` at the back, at least
    ``width`` wider than the neck on each side (but at most ``max_half`` from the neck's
    axis). ``shape``: ``round``, ``square``, ``boat`` (wide) or ``v``.

    Returns:
        the cut and its half-width (the farthest it reaches from the neck's axis in X).

    Raises:
        PatternError: if ``max_half`` leaves no room around the neck.
    """
    x0 = float(m.neck_center[0])
    top = float(torso._top(np.array([x0]))[0][0]) if torso._top is not None else m.z_neck
    section = torso._profile(np.array([m.z_neck - 0.03]))
    cy, bf, bb = float(section[1][0]), float(section[3][0]), float(section[4][0])
    least = m.neck_radius + CLEARANCE + 0.01
    half = m.neck_radius + CLEARANCE + 0.015 + width + (0.05 if shape == "boat" else 0.0)
    half = min(half, max_half)
    if half < least:
        raise PatternError("no room for a neckline between the armholes")
    exponent = 5.0 if shape == "square" else 2.0
    reach = 0.08 + max(front_depth, back_depth)
    # At the front surface (cy − bf) the bottom is front_depth below the top, at the back
    # (cy + bb) back_depth: a tilt linear in y.
    tilt = (front_depth - back_depth) / (bf + bb)
    centre = top - back_depth + reach - tilt * bb
    round_part = EllipseCut("neck", cx=x0, cz=centre, rx=half, rz=reach, p=exponent, cy=cy,
                            tilt=tilt)
    if shape != "v":
        return round_part, half
    # V: the round cut at the back, a V reaching front_depth in front.
    back_only = EllipseCut("neck", cx=x0, cz=top - back_depth + reach, rx=half, rz=reach,
                           cy=cy)
    apex = top - front_depth
    slope = (top - apex) / half
    v_tilt = (front_depth - back_depth) / (bf + bb) * 1.5
    v = VCut("neck", cx=x0, apex_z=apex + v_tilt * bf, slope=slope, cy=cy, tilt=v_tilt)
    return UnionCut("neck", (back_only, v)), half


def armhole_region(m: BodyMeasurements, body_vertices: np.ndarray, torso: Stack, side: str,
                   drop: float) -> tuple[np.ndarray, float, float, float]:
    """The least armhole: a Y-extruded ellipse (centre ``(x, z)``, half-axes ``rx``,
    ``rz``, turned by ``angle`` along the principal axes of the points) holding every arm
    vertex that reaches the torso solid's surface (plus clearance), lowered by ``drop``."""
    from data_prep.garments.measurements import ARM_L, ARM_R

    arm = body_vertices[m.labels == (ARM_L if side == "L" else ARM_R)]
    near = arm[torso(arm) > -3 * CLEARANCE]
    if len(near) == 0:  # the arm never reaches the torso surface: a nominal armhole
        near = np.array([[m.armpits[side][0], 0.0, m.armpits[side][2]],
                         [m.armpits[side][0], 0.0, m.z_shoulder]])
    # Only the part of the arm close to the torso matters (the rest is outside it).
    inner = np.abs(near[:, 0] - m.neck_center[0])
    points = near[inner < inner.min() + 0.08][:, [0, 2]]
    points = np.concatenate([points, points - [0.0, drop]])
    centre = (points.min(axis=0) + points.max(axis=0)) / 2
    spread = points - centre
    _, vectors = np.linalg.eigh(spread.T @ spread)
    major = vectors[:, -1]
    angle = float(np.arctan2(major[1], major[0]))
    local = spread @ vectors[:, ::-1]  # (along major, along minor)
    half = np.abs(local).max(axis=0) + 2 * CLEARANCE
    scale = float(np.sqrt(((local / half) ** 2).sum(axis=1)).max())
    rx, rz = half * max(scale, 1.0)
    return centre, float(rx), float(rz), angle


def _ellipse(side: str, region: tuple, grow: float = 0.0) -> EllipseCut:
    centre, rx, rz, angle = region
    return EllipseCut(f"armhole_{side}", cx=float(centre[0]), cz=float(centre[1]),
                      rx=float(rx + grow), rz=float(rz + grow), angle=angle)


def _strap_gap(neck: Cut, armhole: EllipseCut, depths: np.ndarray) -> float:
    """Roughly the narrowest garment left between a neckline and an armhole (metres):
    the neck cut's value (about a distance) on the armhole's rim, the least over the
    garment's depth."""
    t = np.linspace(0.0, 2 * np.pi, 180, endpoint=False)
    u, w = armhole.rx * np.cos(t), armhole.rz * np.sin(t)
    c, s = np.cos(armhole.angle), np.sin(armhole.angle)
    x, z = armhole.cx + c * u - s * w, armhole.cz + s * u + c * w
    return min(float(neck(np.stack([x, np.full_like(x, y), z], axis=1)).min()) for y in depths)


def _largest(ok: object, low: float, high: float, steps: int = 12) -> float | None:
    """Largest value in ``[low, high]`` where the monotone predicate ``ok`` holds (None if
    not even at ``low``), by bisection."""
    if not ok(low):  # type: ignore[operator]
        return None
    if ok(high):  # type: ignore[operator]
        return high
    for _ in range(steps):
        middle = (low + high) / 2
        low, high = (middle, high) if ok(middle) else (low, middle)  # type: ignore[operator]
    return low


def sleeveless_cuts(m: BodyMeasurements, body_vertices: np.ndarray, torso: Stack, *,
                    drop: float, strap: float, neck_depth: float, back_depth: float,
                    neck_width: float, neckline: str) -> list[Cut]:
    """Neckline and armholes of a sleeveless garment, shoulder straps at least
    :data:`MIN_STRAP` wide: the least armholes (:func:`armhole_region`) fix where the
    arms pass; the neckline is narrowed if it would leave less; then the armholes grow
    until the straps are ``strap`` wide (or as wide as the least armholes allow).

    Raises:
        PatternError: if even the narrowest neckline leaves no strap.
    """
    regions = {side: armhole_region(m, body_vertices, torso, side, drop) for side in ("L", "R")}
    section = torso._profile(np.array([m.z_neck - 0.03]))
    cy, bf, bb = float(section[1][0]), float(section[3][0]), float(section[4][0])
    depths = np.linspace(cy - bf, cy + bb, 5)

    def neck_of(half: float) -> Cut:
        return neck_cut(m, torso, front_depth=neck_depth, back_depth=back_depth,
                        width=neck_width, shape=neckline, max_half=half)[0]

    def fits(half: float) -> bool:
        neck = neck_of(half)
        return all(_strap_gap(neck, _ellipse(side, region), depths) >= MIN_STRAP
                   for side, region in regions.items())

    least = m.neck_radius + CLEARANCE + 0.01
    half = _largest(fits, least, 0.3)
    if half is None:
        raise PatternError("no room for a neckline between the armholes")
    neck = neck_of(half)
    cuts: list[Cut] = [neck]
    for side, region in regions.items():
        grow = _largest(lambda g, region=region, side=side: _strap_gap(
            neck, _ellipse(side, region, g), depths) >= strap, 0.0, 0.2)
        cuts.append(_ellipse(side, region, grow or 0.0))
    return cuts


def hem_cut(z: float, stack: Stack, name: str = "hem", front_rise: float = 0.0) -> PlaneCut:
    """Keep everything above height ``z`` (a hem), through the ``stack``'s centre;
    ``front_rise`` tilts it so its front edge is that much higher than its back edge (a
    high-low hem)."""
    section = stack._profile(np.array([z]))
    cy, depth = float(section[1][0]), float(section[3][0] + section[4][0])
    normal = np.array([0.0, front_rise / depth, 1.0])
    normal /= np.linalg.norm(normal)
    return PlaneCut(name, point=np.array([0.0, cy, z]), normal=normal)


def waist_cut(z: float, name: str = "waist") -> PlaneCut:
    """Keep everything below height ``z``."""
    return PlaneCut(name, point=np.array([0.0, 0.0, z]), normal=np.array([0.0, 0.0, -1.0]))


def hem_low(z_hem: float, front_rise: float) -> float:
    """Lowest point of a (possibly tilted, :func:`hem_cut`) hem: half the rise below."""
    return z_hem - 0.6 * abs(front_rise) - 0.02


def bounds(solids: list[Solid], z_low: float, z_high: float, margin: float = 0.06) -> np.ndarray:
    """``(2, 3)`` box around the solids between two heights (for the pattern grid)."""
    lo = np.array([np.inf, np.inf, z_low - 0.02])
    hi = np.array([-np.inf, -np.inf, z_high + 0.02])
    flat: list[Solid] = []
    for solid in solids:
        flat.extend(solid.parts if isinstance(solid, Group) else [solid])
    for solid in flat:
        if isinstance(solid, Stack):
            keep = (solid.z >= z_low - 0.1) & (solid.z <= z_high + 0.1)
            if not keep.any():
                keep = np.ones(len(solid.z), dtype=bool)
            x_lo = (solid.cx - solid.a)[keep].min()
            x_hi = (solid.cx + solid.a)[keep].max()
            y_lo = (solid.cy - solid.bf)[keep].min()
            y_hi = (solid.cy + solid.bb)[keep].max()
        else:
            r = float(np.max(solid.radius))
            x_lo, x_hi = solid.axis[:, 0].min() - r, solid.axis[:, 0].max() + r
            y_lo, y_hi = solid.axis[:, 1].min() - r, solid.axis[:, 1].max() + r
        lo[:2] = np.minimum(lo[:2], [x_lo, y_lo])
        hi[:2] = np.maximum(hi[:2], [x_hi, y_hi])
    pad = np.array([margin, margin, 0.0])
    return np.stack([lo - pad, hi + pad])


def upper_parts(body_vertices: np.ndarray, m: BodyMeasurements, torso: Stack, *,
                sleeves: str, sleeve_length: float, sleeve_looseness: float,
                sleeve_flare: float, neckline: str, neck_depth: float, back_depth: float,
                neck_width: float, strap: float, armhole_drop: float, top_edge: float
                ) -> tuple[list[Solid], list[Cut], int, str]:
    """Sleeves, neckline and armholes of a garment that covers the chest.

    Args:
        sleeves: ``sleeved`` (tubes along the arms, cut at ``sleeve_length`` of the
            shoulder-to-wrist length), ``sleeveless`` (armholes, straps ``strap`` wide)
            or ``strapless`` (a straight top edge ``top_edge`` metres below the armpits).

    Returns:
        extra solids, cuts, number of openings they make, name of the top opening.
    """
    if sleeves == "strapless":
        z_top = min(m.armpits["L"][2], m.armpits["R"][2]) - top_edge
        return [], [waist_cut(z_top, name="top")], 1, "top"
    solids: list[Solid] = []
    cuts: list[Cut] = []
    if sleeves == "sleeved":
        neck, _ = neck_cut(m, torso, front_depth=neck_depth, back_depth=back_depth,
                           width=neck_width, shape=neckline)
        for side in ("L", "R"):
            tube, cuff = sleeve(m, side, sleeve_length, sleeve_looseness, sleeve_flare)
            solids.append(tube)
            cuts.append(cuff)
    else:
        return [], sleeveless_cuts(m, body_vertices, torso, drop=armhole_drop, strap=strap,
                                   neck_depth=neck_depth, back_depth=back_depth,
                                   neck_width=neck_width, neckline=neckline), 3, "neck"
    return solids, [neck, *cuts], 3, "neck"


#: :func:`upper_parts`' settings: a garment type's style fields of these names set them.
UPPER_SETTINGS = ("sleeves", "sleeve_length", "sleeve_looseness", "sleeve_flare", "neckline",
                  "neck_depth", "back_depth", "neck_width", "strap", "armhole_drop", "top_edge")


def styled_upper_parts(body_vertices: np.ndarray, m: BodyMeasurements, torso: Stack,
                       style: Style, **fixed: Any) -> tuple[list[Solid], list[Cut], int, str]:
    """:func:`upper_parts` with each of :data:`UPPER_SETTINGS` read from the style field
    of that name, except those given in ``fixed`` (what the garment type does not let
    vary: a T-shirt is always sleeved and has no straps).

    Raises:
        AttributeError: if a setting is neither a field of ``style`` nor in ``fixed``.
    """
    settings = {name: getattr(style, name) for name in UPPER_SETTINGS if name not in fixed}
    return upper_parts(body_vertices, m, torso, **settings, **fixed)
