"""A garment's sewing pattern: front and back panels in the frontal (X, Z) plane.

Seen from the front, a garment around a body in T- or A-pose is a flat region Ω
(shirt: a T; trousers: an upside-down U); the garment is a *front* and a *back* panel
of that shape, sewn together along the seams (the silhouette) and left open along the
cuts (hem, cuffs, neck, waist, armholes). We find Ω from the implicit design
(:class:`~data_prep.garments.shapes.Design`) on a 1–2 cm grid: a point is in a panel's
Ω when the line through it along Y enters the garment's solid and no cut removes the
point where that panel's surface is (front and back differ only where a cut is
tilted, e.g. a neckline deeper in front). Each boundary stretch of Ω is a *seam*
(shared by both panels) or an *opening* (one copy per panel). Both panels are
triangulated by conforming Delaunay triangulations with the same seam points but
different random interior points, and stitched along the seams, so the result is a
manifold by construction: every seam edge has one front and one back triangle, and
each opening becomes one closed boundary loop (front half + back half).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from data_prep.garments.shapes import Design


class PatternError(ValueError):
    """The design does not give a usable pattern (e.g. two layers overlap in the frontal
    view, or a cut splits the garment); the sampler draws another design."""


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


@dataclasses.dataclass
class Outline:
    """One panel's boundary as runs: each run is a polyline ``(n, 2)`` from corner to
    corner (consecutive runs share their end points), counter-clockwise in (X, Z), with
    ``label`` 0 for a seam or ``k`` for the opening made by cut ``k − 1``."""

    runs: list[np.ndarray]
    labels: list[int]


def trace(design: Design, sil: Silhouette, side: int) -> Outline:
    """Trace one panel's Ω and split its boundary into seam and opening runs.

    Raises:
        PatternError: if Ω is not one region without holes, or has no opening.
    """
    import contourpy

    lines = contourpy.contour_generator(sil.x, sil.z, sil.region[side]).lines(0.0)
    loops = [line for line in lines if len(line) > 3 and np.allclose(line[0], line[-1])]
    if len(loops) < len(lines):
        raise PatternError("the garment region reaches the edge of its box")
    if not loops:
        raise PatternError("the garment region is empty")

    def area(loop: np.ndarray) -> float:
        return 0.5 * float(np.sum(loop[:-1, 0] * loop[1:, 1] - loop[1:, 0] * loop[:-1, 1]))

    areas = np.array([area(loop) for loop in loops])
    main = int(np.argmax(np.abs(areas)))
    others = np.abs(np.delete(areas, main))
    if (others > 4 * float(sil.x[1] - sil.x[0]) ** 2).any():
        raise PatternError(f"the garment region is not one simple piece ({len(loops)} outlines)")
    loop = loops[main][:-1]
    if areas[main] < 0:  # counter-clockwise in (x, z)
        loop = loop[::-1]
    values = _along_y(design, loop, sil.ys)
    inside, _ = _fold(values, sil.ys)
    front_y, back_y, _ = _crossings(values, sil.ys)
    label = _terms(design, loop, inside, front_y if side < 0 else back_y).argmax(axis=1)
    # Drop label flicker: a run of under 3 points between two runs of one label.
    for _ in range(3):
        changes = np.flatnonzero(label != np.roll(label, 1))
        if len(changes) < 2:
            break
        for start, end in zip(changes, np.roll(changes, -1), strict=True):
            length = (end - start) % len(label)
            if 0 < length < 3 and label[start - 1] == label[end % len(label)]:
                label[np.arange(start, start + length) % len(label)] = label[start - 1]
    changes = np.flatnonzero(label != np.roll(label, 1))
    if len(changes) == 0:
        raise PatternError("the garment has no opening")
    runs, labels = [], []
    for start, end in zip(changes, np.roll(changes, -1), strict=True):
        length = (end - start) % len(loop) or len(loop)
        idx = np.arange(start, start + length + 1) % len(loop)
        run = loop[idx].copy()
        # Corners halfway between the last point of a run and the first of the next.
        run[0] = (loop[start] + loop[start - 1]) / 2
        run[-1] = (loop[end % len(loop)] + loop[end - 1]) / 2
        runs.append(run)
        labels.append(int(label[start]))
    for label_, following in zip(labels, labels[1:] + labels[:1], strict=True):
        if label_ != 0 and following != 0:
            raise PatternError("two openings touch (e.g. a neckline reaching an armhole)")
    return Outline(runs=runs, labels=labels)


@dataclasses.dataclass
class Pattern:
    """Front and back panels sharing their seams.

    ``order`` is the cyclic sequence of runs, the same for both panels: ``(0, i)`` is the
    shared seam run ``seams[i]``, ``(k, i)`` (k >= 1) is opening run ``i`` made by cut
    ``k − 1``, drawn as ``openings[side][i]`` on each panel (side −1 front, +1 back).
    """

    seams: list[np.ndarray]
    openings: dict[int, list[np.ndarray]]
    order: list[tuple[int, int]]

    def boundary(self, side: int) -> list[np.ndarray]:
        """That panel's runs in order (each from corner to corner)."""
        return [self.seams[i] if k == 0 else self.openings[side][i] for k, i in self.order]


def pair(front: Outline, back: Outline) -> Pattern:
    """Align the back outline with the front one and make their seams identical (the
    front's), snapping the back openings' ends onto the shared corners.

    Raises:
        PatternError: if the two panels do not have the same sequence of runs.
    """
    if len(front.runs) != len(back.runs) or sorted(front.labels) != sorted(back.labels):
        raise PatternError("front and back panels have different openings")
    count = len(front.runs)
    first_seam = front.labels.index(0)
    start = front.runs[first_seam][0]
    candidates = [i for i in range(count) if back.labels[i] == 0]
    shift = min(candidates, key=lambda i: float(np.linalg.norm(back.runs[i][0] - start)))
    shift = (shift - first_seam) % count
    back_runs = back.runs[shift:] + back.runs[:shift]
    back_labels = back.labels[shift:] + back.labels[:shift]
    if back_labels != front.labels:
        raise PatternError("front and back panels have different openings")
    seams, openings, order = [], {-1: [], 1: []}, []
    for i, label in enumerate(front.labels):
        if label == 0:
            order.append((0, len(seams)))
            seams.append(front.runs[i])
        else:
            before, after = front.runs[i - 1], front.runs[(i + 1) % count]
            back_run = back_runs[i].copy()
            back_run[0], back_run[-1] = before[-1], after[0]
            order.append((label, len(openings[-1])))
            openings[-1].append(front.runs[i])
            openings[1].append(back_run)
    return Pattern(seams=seams, openings=openings, order=order)


def resample(polyline: np.ndarray, lengths: np.ndarray, spacing: float) -> np.ndarray:
    """Points along ``polyline (n, 2)`` equally spaced in the arc length measured by
    ``lengths (n − 1,)`` (the 3D lengths of its segments), both ends kept."""
    arc = np.concatenate([[0.0], np.cumsum(lengths)])
    count = max(round(float(arc[-1] / spacing)), 1)
    targets = np.linspace(0.0, arc[-1], count + 1)
    return np.stack([np.interp(targets, arc, polyline[:, k]) for k in range(2)], axis=1)


@dataclasses.dataclass
class PanelMesh:
    """Stitched front + back panels.

    Attributes:
        xz: ``(N, 2)`` pattern position of every vertex.
        side: ``(N,)`` −1 front, +1 back, 0 seam (shared).
        faces: ``(F, 3)`` outward-facing (front triangles counter-clockwise seen from −Y).
        opening: ``(N,)`` the cut index + 1 of a vertex on an opening, 0 elsewhere
            (seam corners carry their opening's label).
    """

    xz: np.ndarray
    side: np.ndarray
    faces: np.ndarray
    opening: np.ndarray


def _diametral_conflicts(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """``(P,)`` True where a point lies in (1.2×) the diametral circle of a boundary
    segment ``(S, 2, 2)``: such a point keeps the segment out of a Delaunay mesh."""
    mids = segments.mean(axis=1)
    radius = 0.6 * np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    tree = cKDTree(mids)
    k = min(8, len(mids))
    distance, idx = tree.query(points, k=k)
    distance = distance.reshape(len(points), k)
    idx = idx.reshape(len(points), k)
    return (distance < radius[idx]).any(axis=1)


def _inside_polygon(polygon: np.ndarray, points: np.ndarray) -> np.ndarray:
    from matplotlib.path import Path

    return Path(polygon).contains_points(points)


def _interior_points(polygon: np.ndarray, count: int, rng: np.random.Generator) -> np.ndarray:
    """About ``count`` jittered-grid points inside ``polygon`` and clear of its segments'
    diametral circles: the lattice spacing is set from the polygon's area, then corrected
    once for the points lost along the boundary."""
    area = 0.5 * abs(float(np.sum(polygon[:, 0] * np.roll(polygon[:, 1], -1)
                                  - np.roll(polygon[:, 0], -1) * polygon[:, 1])))
    segments = np.stack([polygon, np.roll(polygon, -1, axis=0)], axis=1)
    # A triangular lattice of spacing h holds 2 / (√3 h²) points per unit area.
    spacing = float(np.sqrt(2.0 * area / (np.sqrt(3.0) * max(count, 1))))
    state = rng.bit_generator.state
    kept = len(_clear(_jittered_points(polygon, spacing, rng), segments))
    rng.bit_generator.state = state  # same draws, finer grid: reproducible per seed
    spacing *= float(np.sqrt(max(kept, 1) / max(count, 1)))
    return _clear(_jittered_points(polygon, spacing, rng), segments)


def _clear(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    return points[~_diametral_conflicts(points, segments)] if len(points) else points


def _jittered_points(polygon: np.ndarray, spacing: float, rng: np.random.Generator) -> np.ndarray:
    """Jittered grid points (±35 % of a cell) inside ``polygon``, rows offset by half a
    cell (a triangular lattice, so Delaunay gives valences around 6, varied by the
    jitter)."""
    lo, hi = polygon.min(axis=0), polygon.max(axis=0)
    row_step = spacing * np.sqrt(3) / 2
    rows = np.arange(lo[1], hi[1] + row_step, row_step)
    cols = np.arange(lo[0] - spacing, hi[0] + spacing, spacing)
    xx, zz = np.meshgrid(cols, rows)
    xx = xx + 0.5 * spacing * (np.arange(len(rows)) % 2)[:, None]
    points = np.stack([xx.ravel(), zz.ravel()], axis=1)
    points += rng.uniform(-0.35, 0.35, points.shape) * np.array([spacing, row_step])
    return points[_inside_polygon(polygon, points)]


def _split(run: np.ndarray, missing: np.ndarray) -> np.ndarray:
    """Insert the midpoint of each segment of ``run`` flagged in ``missing (n − 1,)``."""
    pieces = []
    for i in range(len(run) - 1):
        pieces.append(run[i])
        if missing[i]:
            pieces.append((run[i] + run[i + 1]) / 2)
    pieces.append(run[-1])
    return np.array(pieces)


def _shared_ids(pattern: Pattern, side: int) -> np.ndarray:
    """Per boundary point of one panel (in :meth:`Pattern.boundary` order): the index of
    the shared (seam) vertex it is, numbering seam points run by run, or −1 for a point
    of that panel's own opening."""
    first = np.cumsum([0] + [len(run) for run in pattern.seams])
    ids = []
    for position, ((kind, i), run) in enumerate(zip(pattern.order, pattern.boundary(side),
                                                    strict=True)):
        if kind == 0:
            ids.append(first[i] + np.arange(len(run) - 1))
        else:
            previous = pattern.order[position - 1][1]
            ids.append(np.concatenate([[first[previous] + len(pattern.seams[previous]) - 1],
                                       np.full(len(run) - 2, -1)]))
    return np.concatenate(ids).astype(np.int64)


def _triangulate_panel(boundary: np.ndarray, interior: np.ndarray, forced: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Delaunay triangulation of one panel.

    Returns:
        points ``(B + I, 2)`` (boundary first), triangles inside the polygon ``(T, 3)``
        (empty if not conforming) and ``missing (B,)``: boundary segments (i → i + 1)
        that are not edges, or touch a point no triangle uses.
    """
    segments = np.stack([boundary, np.roll(boundary, -1, axis=0)], axis=1)
    interior = interior[~_diametral_conflicts(interior, segments)] if len(interior) else interior
    points = np.concatenate([boundary, interior, forced])
    # Guard points far outside: the polygon is then strictly inside the convex hull, so
    # Qhull never makes flat slivers out of collinear boundary points on the hull.
    centre, span = boundary.mean(axis=0), float(np.ptp(boundary, axis=0).max())
    angles = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    guards = centre + 2 * span * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    tri = Delaunay(np.concatenate([points, guards])).simplices
    tri = tri[(tri < len(points)).all(axis=1)]
    b = np.arange(len(boundary))
    nxt = (b + 1) % len(b)
    keys = np.minimum(b, nxt) * len(points) + np.maximum(b, nxt)
    missing = ~np.isin(keys, _edge_set(tri, len(points)))
    if missing.any():
        return points, np.zeros((0, 3), dtype=np.int64), missing
    tri = _inside_triangles(points, tri, len(boundary))
    _check_panel(tri, len(boundary), len(points))
    used = np.zeros(len(points), dtype=bool)
    used[tri.ravel()] = True
    orphan = ~used[: len(boundary)]
    missing = orphan | np.roll(orphan, -1)  # split the segments around an orphan point
    # Interior points no triangle uses (Qhull drops exact duplicates) are removed.
    keep = used.copy()
    keep[: len(boundary)] = True
    remap = np.cumsum(keep) - 1
    return points[keep], remap[tri], missing


def triangulate(pattern: Pattern, interior_count: dict[int, int],
                rng: np.random.Generator) -> PanelMesh:
    """Mesh both panels (conforming Delaunay) and stitch them along the seams.

    Both panels share the seam points, so an edge between two seam points that is not
    a seam segment (a chord cutting off a corner, or across a narrow strap) must not be
    in both panels: it would carry four triangles (see :func:`_conflicts`). Boundary
    segments a panel's Delaunay mesh misses are split and both panels meshed again.

    Args:
        pattern: the panels, boundaries already resampled (consecutive points = edges).
        interior_count: per side, how many interior points to place (a jittered grid).
        rng: random generator for the interior points (different per panel).

    Raises:
        PatternError: if a clean triangulation cannot be found.
    """
    seams = [run.copy() for run in pattern.seams]
    openings = {side: [run.copy() for run in runs] for side, runs in pattern.openings.items()}
    interiors: dict[int, np.ndarray] = {}
    forced: dict[int, np.ndarray] = {-1: np.zeros((0, 2)), 1: np.zeros((0, 2))}
    for _attempt in range(20):
        current = Pattern(seams=seams, openings=openings, order=pattern.order)
        panels, clean = {}, True
        seam_missing = [np.zeros(len(run) - 1, dtype=bool) for run in seams]
        for side in (-1, 1):
            runs = current.boundary(side)
            boundary = np.concatenate([run[:-1] for run in runs])
            if side not in interiors:
                interiors[side] = _interior_points(boundary, interior_count[side], rng)
            points, tri, missing = _triangulate_panel(boundary, interiors[side], forced[side])
            panels[side] = (boundary, points[len(boundary):], tri)
            if missing.any():
                clean = False
                offset = 0
                for (kind, i), run in zip(current.order, runs, strict=True):
                    flags = missing[offset: offset + len(run) - 1]
                    if kind == 0:
                        seam_missing[i] |= flags
                    elif flags.any():
                        openings[side][i] = _split(run, flags)
                    offset += len(run) - 1
        if clean:
            extra = _conflicts(current, panels)
            if not any(len(points) for points in extra.values()):
                return _stitch(current, panels)
            for side, points in extra.items():
                forced[side] = np.concatenate([forced[side], points])
        seams = [_split(run, flags) if flags.any() else run
                 for run, flags in zip(seams, seam_missing, strict=True)]
    raise PatternError("could not build a conforming triangulation of the pattern")


def _segments_cross(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray) -> bool:
    """True if segments ``p–q`` and ``r–s`` (2D) cross at a point inside both."""
    def orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    return (orient(p, q, r) * orient(p, q, s) < 0) and (orient(r, s, p) * orient(r, s, q) < 0)


def _conflicts(pattern: Pattern, panels: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]
               ) -> dict[int, np.ndarray]:
    """Resolve what would break the stitched mesh; return points to add (per panel) if
    the panels must be meshed again (nothing to add: ``panels`` is ready to stitch).

    A chord between two seam points in both panels is flipped in the back panel (the
    other diagonal of its quad) when that quad is convex, else a point is added on the
    back panel's side of it.
    """
    chords, extra = {}, {-1: [], 1: []}
    for side in (-1, 1):
        boundary, _, tri = panels[side]
        count = len(boundary)
        ids = _shared_ids(pattern, side)
        edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        edges = np.unique(edges, axis=0)
        on_boundary = (edges < count).all(axis=1)
        consecutive = ((edges[:, 1] - edges[:, 0]) % count == 1) | (
            (edges[:, 0] - edges[:, 1]) % count == 1)
        chord = edges[on_boundary & ~consecutive]
        shared = (ids[chord] >= 0).all(axis=1)
        chords[side] = {(int(min(ids[a], ids[b])), int(max(ids[a], ids[b]))): (int(a), int(b))
                        for a, b in chord[shared]}
    boundary, interior, tri = panels[1]
    points = np.concatenate([boundary, interior])
    tri = tri.copy()
    for key in chords[-1].keys() & chords[1].keys():
        a, b = chords[1][key]
        holding = np.flatnonzero(((tri == a) | (tri == b)).sum(axis=1) == 2)
        if len(holding) != 2:
            continue
        c = int(np.setdiff1d(tri[holding[0]], [a, b])[0])
        d = int(np.setdiff1d(tri[holding[1]], [a, b])[0])
        if _segments_cross(points[a], points[b], points[c], points[d]):
            tri[holding[0]] = [a, c, d]
            tri[holding[1]] = [b, d, c]
        else:
            inner = d if d >= len(boundary) else c
            extra[1].append((points[a] + points[b]) / 2 * 0.7 + 0.3 * points[inner])
    panels[1] = (boundary, interior, tri)
    return {side: np.array(found).reshape(-1, 2) for side, found in extra.items()}


def _inside_triangles(points: np.ndarray, tri: np.ndarray, count: int) -> np.ndarray:
    """The triangles inside the polygon ``points[:count]`` (counter-clockwise), given a
    triangulation that contains every polygon edge: the triangles connected to the left
    side of a polygon edge without crossing one. Robust where a centroid test is not
    (slivers along the boundary)."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    n = len(points)
    edges = np.stack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]], axis=1)  # (T, 3, 2)
    third = tri[:, [2, 0, 1]]
    key = np.sort(edges, axis=2)
    key = key[..., 0] * n + key[..., 1]
    b = np.arange(count)
    polygon_key = np.minimum(b, (b + 1) % count) * n + np.maximum(b, (b + 1) % count)
    on_polygon = np.isin(key, polygon_key)
    # Triangles sharing an edge that is not a polygon edge are on the same side.
    flat_key = key.ravel()
    owner = np.repeat(np.arange(len(tri)), 3)
    order = np.argsort(flat_key, kind="stable")
    sorted_key = flat_key[order]
    pair = np.flatnonzero((sorted_key[1:] == sorted_key[:-1]) & ~on_polygon.ravel()[order[1:]])
    first, second = owner[order[pair]], owner[order[pair + 1]]
    graph = sp.coo_matrix((np.ones(len(pair)), (first, second)), shape=(len(tri), len(tri)))
    _, component = connected_components(graph, directed=False)
    # A triangle on a polygon edge is inside if its third vertex is left of the edge
    # as the polygon runs (i -> i + 1).
    t, e = np.nonzero(on_polygon)
    start, end = edges[t, e, 0], edges[t, e, 1]
    forward = (end - start) % count == 1
    tail, head = np.where(forward, start, end), np.where(forward, end, start)
    d, v = points[head] - points[tail], points[third[t, e]] - points[tail]
    left = d[:, 0] * v[:, 1] - d[:, 1] * v[:, 0] > 0
    inside_components = np.zeros(component.max() + 1, dtype=bool)
    inside_components[component[t[left]]] = True
    return tri[inside_components[component]]


def _check_panel(tri: np.ndarray, count: int, n: int) -> None:
    """A panel must be a disk bounded by the polygon: each polygon edge in one triangle,
    every other edge in two (a sliver outside the polygon would break this)."""
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    keys, counts = np.unique(edges[:, 0] * n + edges[:, 1], return_counts=True)
    b = np.arange(count)
    polygon = np.minimum(b, (b + 1) % count) * n + np.maximum(b, (b + 1) % count)
    on_polygon = np.isin(keys, polygon)
    if (counts[on_polygon] != 1).any() or (counts[~on_polygon] != 2).any() or (
            on_polygon.sum() != count):
        raise PatternError("a pattern panel did not triangulate as a disk")


def _edge_set(tri: np.ndarray, n: int) -> np.ndarray:
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    edges = np.sort(edges, axis=1)
    return np.unique(edges[:, 0] * n + edges[:, 1])


def _stitch(pattern: Pattern, panels: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]
            ) -> PanelMesh:
    xz, side_of, opening = [], [], []
    seam_index = []
    # Shared vertices: every point of every seam run, corners included (a corner joins
    # the front and back halves of its opening's loop).
    corner_label: dict[tuple[int, int], int] = {}
    for position, (kind, _) in enumerate(pattern.order):
        if kind != 0:
            prev_i = pattern.order[position - 1][1]
            next_i = pattern.order[(position + 1) % len(pattern.order)][1]
            corner_label[(prev_i, -1)] = kind  # end of the seam before this opening
            corner_label[(next_i, 0)] = kind  # start of the seam after it
    for i, run in enumerate(pattern.seams):
        first = len(xz)
        for j, point in enumerate(run):
            xz.append(point)
            side_of.append(0)
            label = corner_label.get((i, 0), 0) if j == 0 else (
                corner_label.get((i, -1), 0) if j == len(run) - 1 else 0)
            opening.append(label)
        seam_index.append(first + np.arange(len(run)))
    faces = []
    for side in (-1, 1):
        boundary, interior, tri = panels[side]
        runs = pattern.boundary(side)
        index = []
        for (kind, i), run in zip(pattern.order, runs, strict=True):
            if kind == 0:
                index.append(seam_index[i][:-1])
            else:
                # An opening run's ends are the neighbouring seams' corners.
                own = len(xz) + np.arange(len(run) - 2)
                xz.extend(run[1:-1])
                side_of.extend([side] * (len(run) - 2))
                opening.extend([kind] * (len(run) - 2))
                previous_seam = pattern.order[(pattern.order.index((kind, i)) - 1)][1]
                index.append(np.concatenate([[seam_index[previous_seam][-1]], own]))
        index = np.concatenate(index)
        if len(index) != len(boundary):
            raise PatternError("internal error: boundary bookkeeping mismatch")
        interior_index = len(xz) + np.arange(len(interior))
        xz.extend(interior)
        side_of.extend([side] * len(interior))
        opening.extend([0] * len(interior))
        local_to_global = np.concatenate([index, interior_index])
        points = np.concatenate([boundary, interior])
        corners = points[tri]
        cross = ((corners[:, 1, 0] - corners[:, 0, 0]) * (corners[:, 2, 1] - corners[:, 0, 1])
                 - (corners[:, 1, 1] - corners[:, 0, 1]) * (corners[:, 2, 0] - corners[:, 0, 0]))
        # Counter-clockwise in (x, z) faces −Y (x × z = −y): outward on the front panel.
        ccw = np.where((cross > 0)[:, None], tri, tri[:, [0, 2, 1]])
        oriented = ccw if side < 0 else ccw[:, [0, 2, 1]]
        faces.append(local_to_global[oriented])
    return PanelMesh(xz=np.asarray(xz, dtype=np.float64), side=np.asarray(side_of, dtype=np.int64),
                     faces=np.concatenate(faces).astype(np.int64),
                     opening=np.asarray(opening, dtype=np.int64))
