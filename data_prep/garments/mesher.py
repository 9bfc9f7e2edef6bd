"""From an implicit design to a clean triangle mesh around the body.

1. :mod:`.pattern` (with :mod:`.silhouette`, :mod:`.panel_boundary`,
   :mod:`.panel_triangulation`) turns the design into stitched front/back panels (the topology and
   a first placement: each panel point is lifted along Y onto the design's surface).
2. :func:`relax` evens the mesh out on that surface: tangential umbrella smoothing,
   then a Newton step back onto the surface; opening vertices slide along their loop
   and are projected onto the curve where the surface meets their cut. Vertices drift
   freely across the side folds, so the seams leave no trace in the geometry. Between
   relaxations, :func:`~.flips.delaunay_flips` removes the slivers of the flat pattern.
3. :func:`push_out` moves any vertex closer to the body than the clearance outward
   (along the direction from the closest body point), spread smoothly over neighbours.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

from data_prep.garments.body_distance import BodyDistance
from data_prep.garments.errors import PatternError
from data_prep.garments.flips import delaunay_flips
from data_prep.garments.panel_boundary import trace
from data_prep.garments.panel_triangulation import triangulate
from data_prep.garments.pattern import Pattern, pair, resample
from data_prep.garments.shapes import Design, gradient
from data_prep.garments.silhouette import Silhouette, lift_on_grid, silhouette, surface_area
from data_prep.garments.stitching import PanelMesh
from gnngarment.geometry.boundary import boundary_loops as geometry_boundary_loops

MAX_STEP = 0.02  # metres: largest Newton step onto the surface (no jumps across gaps)


@dataclasses.dataclass
class GarmentMesh:
    """A meshed design.

    Attributes:
        pos: ``(N, 3)`` metres. faces: ``(F, 3)`` outward-facing.
        loops: opening name → ``(L,)`` vertex indices of its boundary loop, in order.
    """

    pos: np.ndarray
    faces: np.ndarray
    loops: dict[str, np.ndarray]


def adjacency(faces: np.ndarray, n: int) -> sp.csr_matrix:
    """``(n, n)`` 0/1 vertex adjacency of a triangle mesh."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    rows = np.concatenate([edges[:, 0], edges[:, 1]])
    cols = np.concatenate([edges[:, 1], edges[:, 0]])
    matrix = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n)).tocsr()
    matrix.data[:] = 1.0
    return matrix


def boundary_loops(faces: np.ndarray) -> list[np.ndarray]:
    """:func:`gnngarment.geometry.boundary.boundary_loops`, failing as a pattern does.

    Raises:
        PatternError: a boundary vertex is on two loops (the sampler retries).
    """
    try:
        return geometry_boundary_loops(faces)
    except ValueError as error:
        raise PatternError(str(error)) from None


GRID_DENSE = 0.002  # metres: pattern spacing at which seam/opening lengths are measured
MIN_OPENING_EDGES = 4  # least edges of one panel's half of an opening


def _lengths(points: np.ndarray) -> np.ndarray:
    return np.linalg.norm(np.diff(points, axis=0), axis=1)


def _resample_run(sil: Silhouette, run: np.ndarray, side: int, edge: float) -> np.ndarray:
    """Resample a pattern run with as many segments as its lifted (3D) length holds
    ``edge``-long edges, evenly spaced in the pattern: near a fold the 3D spacing would
    crowd the points in the pattern (slivers); :func:`relax` evens them out along the
    loop in 3D anyway."""
    dense = resample(run, _lengths(run), GRID_DENSE)
    length_3d = float(_lengths(lift_on_grid(sil, dense, np.full(len(dense), side))).sum())
    flat = _lengths(dense)
    # Openings get at least four edges per panel: a loop of fewer collapses in relax.
    least = 1 if side == 0 else MIN_OPENING_EDGES
    return resample(dense, flat, float(flat.sum()) / max(round(length_3d / edge), least))


def build_panels(design: Design, target_vertices: int,
                 rng: np.random.Generator) -> tuple[PanelMesh, np.ndarray, float]:
    """Pattern → stitched panels, their lifted positions ``(N, 3)`` and the target edge
    length (metres) for about ``target_vertices`` vertices."""
    # A coarser silhouette grid for coarse meshes (a third of a rough edge length, from
    # the box: two panels filling about half of it), 1–2 cm.
    size = design.bounds[1] - design.bounds[0]
    rough_edge = np.sqrt(2.0 * size[0] * size[2] / (np.sqrt(3.0) * target_vertices))
    sil = silhouette(design, grid=float(np.clip(rough_edge / 3, 0.01, 0.02)))
    area, flat = surface_area(sil)
    # Equilateral triangles of side e hold 2 / (√3 e²) vertices per unit area.
    edge = float(np.sqrt(2.0 * area / (np.sqrt(3.0) * target_vertices)))
    pattern = pair(trace(design, sil, -1), trace(design, sil, 1))
    pattern = Pattern(
        seams=[_resample_run(sil, run, 0, edge) for run in pattern.seams],
        openings={side: [_resample_run(sil, run, side, edge) for run in runs]
                  for side, runs in pattern.openings.items()},
        order=pattern.order)
    seam_points = sum(len(run) - 1 for run in pattern.seams)
    interior = {}
    for side in (-1, 1):
        own = sum(len(run) - 1 for run in pattern.openings[side])
        # Split the remaining vertices between the panels by their share of the area.
        share = flat[side] / (flat[-1] + flat[1])
        interior[side] = max(round(float(share * (target_vertices - seam_points) - own)), 8)
    panels = triangulate(pattern, interior, rng)
    pos = lift_on_grid(sil, panels.xz, panels.side)
    return panels, pos, edge


def _clamp(step: np.ndarray, limit: float = MAX_STEP) -> np.ndarray:
    length = np.linalg.norm(step, axis=1, keepdims=True)
    return step * np.minimum(1.0, limit / np.maximum(length, 1e-15))


def _curve_step(pos: np.ndarray, f: np.ndarray, gf: np.ndarray, cuts: list[object],
                cut_of: np.ndarray) -> np.ndarray:
    """One Gauss–Newton step towards ``{field = 0} ∩ {cut = 0}`` for each point: the
    minimum-norm step solving the two linearised equations. ``f (P,)`` and ``gf (P, 3)``
    are the field and its gradient at ``pos (P, 3)``; point i uses ``cuts[cut_of[i]]``."""
    c = np.empty(len(pos))
    gc = np.empty_like(pos)
    for k in np.unique(cut_of):
        mine = cut_of == k
        c[mine] = cuts[k](pos[mine])  # type: ignore[operator]
        gc[mine] = gradient(cuts[k], pos[mine], value=c[mine])
    a, b, d = (gf * gf).sum(1), (gf * gc).sum(1), (gc * gc).sum(1)
    det = a * d - b * b
    ok = det > 1e-12 * np.maximum(a * d, 1e-30)
    det = np.where(ok, det, 1.0)
    # (J Jᵀ)⁻¹ r with J = [gf; gc], r = [f; c]
    u = np.where(ok, (d * f - b * c) / det, f / np.maximum(a, 1e-12))
    w = np.where(ok, (-b * f + a * c) / det, 0.0)
    return -_clamp(u[:, None] * gf + w[:, None] * gc)


def relax(design: Design, pos: np.ndarray, faces: np.ndarray, loops: list[np.ndarray],
          loop_cuts: list[object], iterations: int = 20, rate: float = 0.5,
          margin: float = 0.0, settle: int = 3) -> np.ndarray:
    """Even out the mesh on the design's surface (see the module docstring).

    ``iterations`` smoothing steps are followed by ``settle`` steps that only project.
    Interior vertices are kept at least ``margin`` metres inside every cut, so smoothing
    never drags one across an opening's rim (a fold where the loop is short, e.g. the
    cuff of a thin sleeve on a coarse mesh).

    Shapes:
        pos: ``(N, 3)``, faces: ``(F, 3)``; ``loops[i]`` ``(L_i,)`` ordered loop vertices
        that stay on the curve of cut ``loop_cuts[i]``. Returns ``(N, 3)``.
    """
    n = len(pos)
    matrix = adjacency(faces, n)
    degree = np.asarray(matrix.sum(axis=1)).ravel()
    loop_vertices = np.concatenate(loops)
    cut_of = np.concatenate([np.full(len(loop), i) for i, loop in enumerate(loops)])
    # Each loop vertex's neighbours along its loop.
    before = np.concatenate([np.roll(loop, 1) for loop in loops])
    after = np.concatenate([np.roll(loop, -1) for loop in loops])
    on_loop = np.zeros(n, dtype=bool)
    on_loop[loop_vertices] = True
    interior = np.flatnonzero(~on_loop)
    for step in range(iterations + settle):
        value, grad = design.field_and_gradient(pos)
        newton = _clamp(-value[:, None] * grad
                        / np.maximum((grad**2).sum(axis=1), 1e-12)[:, None])
        rim = pos[loop_vertices]
        if step < iterations:  # smooth, then (the last ``settle`` rounds) only project
            normal = grad / np.maximum(np.linalg.norm(grad, axis=1, keepdims=True), 1e-12)
            delta = matrix @ pos / degree[:, None] - pos
            delta -= (delta * normal).sum(axis=1, keepdims=True) * normal
            moved = pos + rate * delta + newton
            # Loop vertices slide along their loop, then go back onto its curve (the
            # step is taken where they landed: a short loop would otherwise shrink).
            rim = rim + rate * (0.5 * (pos[before] + pos[after]) - rim)
        else:
            moved = pos + newton
        for _ in range(2):
            rim_value, rim_grad = design.field_and_gradient(rim)
            rim = rim + _curve_step(rim, rim_value, rim_grad, list(loop_cuts), cut_of)
        moved[loop_vertices] = rim
        pos = moved
        if margin > 0:
            pos[interior] = _keep_inside(design, pos[interior], margin)
    return pos


def _keep_inside(design: Design, points: np.ndarray, margin: float) -> np.ndarray:
    """Move points closer than ``margin`` to a cut (or beyond it) back to ``margin``
    inside, along the cut's gradient (the next Newton step returns them to the surface)."""
    for cut in design.cuts:
        value = cut(points)  # type: ignore[operator]
        close = np.flatnonzero(value < margin)
        if len(close) == 0:
            continue
        grad = gradient(cut, points[close], value=value[close])
        step = (margin - value[close])[:, None] * grad / np.maximum(
            (grad**2).sum(axis=1), 1e-12)[:, None]
        points[close] += _clamp(step)
    return points


def push_out(pos: np.ndarray, faces: np.ndarray, body: BodyDistance, clearance: float,
             rounds: int = 4) -> tuple[np.ndarray, float]:
    """Move vertices closer than ``clearance`` (metres) to the body outward, smoothly;
    likewise the corners of a face whose centre is closer than half of it (a bump of
    the body between the vertices).

    Returns:
        ``(N, 3)`` positions and the smallest signed body distance of a vertex after the
        last round.
    """
    matrix = adjacency(faces, len(pos))
    degree = np.asarray(matrix.sum(axis=1)).ravel()
    distance = np.zeros(len(pos))
    for round_ in range(rounds + 1):
        distance, _, direction = body.query(pos, exact_below=2 * clearance)
        if round_ == rounds:
            break
        need = np.clip(clearance - distance, 0.0, None)
        push = need[:, None] * direction
        centre_distance, _, centre_direction = body.query(pos[faces].mean(axis=1),
                                                          exact_below=clearance)
        low = np.flatnonzero(centre_distance < 0.5 * clearance)
        for corner in range(3):
            np.add.at(push, faces[low, corner],
                      (clearance - centre_distance[low])[:, None] * centre_direction[low] / 3)
        short = np.linalg.norm(push, axis=1) > 0
        if not short.any():
            break
        fixed = push * 1.1
        shift = fixed
        # Spread the push over a few rings of neighbours so no single vertex spikes out.
        for _ in range(3):
            shift = np.where(short[:, None], fixed, matrix @ shift / degree[:, None])
        pos = pos + shift
    return pos, float(distance.min())


def mesh_design(design: Design, body: BodyDistance, target_vertices: int,
                rng: np.random.Generator, clearance: float = 0.01,
                iterations: int = 20) -> GarmentMesh:
    """Mesh a design around a body: pattern, lift, relax, push out (module docstring).

    Args:
        design: the implicit garment.
        body: signed distance to the body.
        target_vertices: approximate vertex count.
        rng: random generator (interior points of the pattern).
        clearance: minimum distance (metres) of every vertex from the body.
        iterations: smoothing steps in all (split over three relaxations).

    Raises:
        PatternError: the design cannot be meshed cleanly (the sampler retries).
    """
    panels, pos, edge = build_panels(design, target_vertices, rng)
    loops = boundary_loops(panels.faces)
    loop_cuts = []
    for loop in loops:
        labels = panels.opening[loop]
        labels = labels[labels > 0]
        if len(labels) == 0:
            raise PatternError("a boundary loop belongs to no opening")
        loop_cuts.append(design.cuts[int(np.bincount(labels).argmax()) - 1])
    faces = panels.faces
    # Relax, fix slivers by flips, and again; a last relaxation evens out what the flips
    # changed (a sliver along a loop cannot be flipped, only moved).
    rounds = (iterations * 2 // 5, iterations * 2 // 5, iterations - 4 * (iterations // 5))
    for index, count in enumerate(rounds):
        pos = relax(design, pos, faces, loops, loop_cuts, iterations=count, margin=0.25 * edge,
                    settle=3 if index == 2 else 0)
        if index < 2:
            faces = delaunay_flips(pos, faces)
    pos, _ = push_out(pos, faces, body, clearance)
    named: dict[str, np.ndarray] = {}
    for loop, cut in zip(loops, loop_cuts, strict=True):
        name = cut.name  # type: ignore[attr-defined]
        if sum(c is cut for c in loop_cuts) > 1:
            name = f"{name}_{'L' if pos[loop, 0].mean() > 0 else 'R'}"
        if name in named:
            raise PatternError(f"two openings named {name!r}")
        named[name] = loop
    return GarmentMesh(pos=pos, faces=faces, loops=named)
