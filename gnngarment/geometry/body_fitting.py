"""Carry a garment modelled on another body onto the rest body.

A garment from SNUG, NCS, a DCC tool or a scan was made on *its* body: another model
(SMPL, a mannequin), other units, another up axis, another origin. Three steps bring it
onto ours, all pure numpy/scipy:

1. :func:`align_bodies` — a similarity transform ``x ↦ s R x + t`` of the source body
   onto the rest body: ``R`` is the axis-aligned turn (24 candidates: which axis is up,
   which way the body faces) whose scaled, centred body is closest to the rest body in
   the symmetric surface (chamfer) distance; ``s`` matches the heights, so units need
   no guessing; ``t`` and ``s`` are refined by a few steps of iterative closest points.
2. :func:`register_bodies` — a non-rigid fit of the aligned source body onto the rest
   body surface: iterated closest-point correspondences in both directions (rejected
   where the normals disagree, e.g. an inner thigh matched to the other thigh), their
   displacements smoothed over the source mesh, coarse to fine.
3. :func:`carry_garment` — every garment vertex moves by the distance-weighted mean
   displacement of its nearest source-body vertices, smoothed over the garment mesh, so
   that the garment keeps its offset from the body surface it was made on.

:func:`fit_garment` runs the three. What it cannot do: a source body in another pose
(an A-pose garment on our T-pose body keeps its arms down; the correspondence stops
at the armpits).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from gnngarment.geometry.graph import adjacency_matrix, edge_index_from_faces
from gnngarment.geometry.normals import vertex_normals
from gnngarment.geometry.surface_sampling import surface_samples

#: Surface samples per body for the alignment's distances (area-uniform, fixed seed).
ALIGNMENT_SAMPLES = 4000
#: Plausible height ratio of two adult bodies after unit scaling (a body 0.5–2× ours
#: is a child or another model; outside that the "body" is probably not a body).
SCALE_RANGE = (1e-4, 1e4)


@dataclass(frozen=True)
class BodyAlignment:
    """``x ↦ scale · rotation @ x + translation``: the source body's frame onto ours.

    Attributes:
        rotation: ``(3, 3)`` an axis-aligned proper rotation.
        scale: uniform scale (also converts units: 0.01 for a body in centimetres).
        translation: ``(3,)`` metres.
        chamfer: mean symmetric surface distance after the alignment (metres).
        runner_up: the same for the second-best turn (how clear the choice was).
    """

    rotation: np.ndarray
    scale: float
    translation: np.ndarray
    chamfer: float
    runner_up: float

    def apply(self, points: np.ndarray) -> np.ndarray:
        """``(N, 3)`` points of the source frame in the rest body's frame."""
        return self.scale * (np.asarray(points, dtype=np.float64) @ self.rotation.T) \
            + self.translation

    def describe(self) -> str:
        """The turn, scale and translation in words, e.g. for a progress line."""
        names = ["x", "y", "z"]
        up = int(np.argmax(np.abs(self.rotation[2])))
        sign = "+" if self.rotation[2, up] > 0 else "−"
        return (f"source up axis {sign}{names[up]}, scale ×{self.scale:.4g}, translation "
                f"({self.translation[0]:+.3f}, {self.translation[1]:+.3f}, "
                f"{self.translation[2]:+.3f}) m, body-to-body distance "
                f"{1000 * self.chamfer:.0f} mm (next best turn {1000 * self.runner_up:.0f} mm)")


@dataclass(frozen=True)
class FittedGarment:
    """A garment carried onto the rest body.

    Attributes:
        pos: ``(N, 3)`` garment vertices on the rest body (metres, Z up).
        alignment: the source body's similarity transform.
        source_body: ``(N_s, 3)`` the source body after alignment and registration (on
            the rest body's surface, in the source topology).
        registration_error: mean distance of the registered source body to the rest
            body surface (metres).
    """

    pos: np.ndarray
    alignment: BodyAlignment
    source_body: np.ndarray
    registration_error: float


def axis_turns() -> list[np.ndarray]:
    """The 24 proper rotations that map coordinate axes onto signed coordinate axes."""
    turns = []
    for order in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            matrix = np.zeros((3, 3))
            matrix[np.arange(3), order] = signs
            if np.linalg.det(matrix) > 0:
                turns.append(matrix)
    return turns


def _chamfer(points: np.ndarray, tree: cKDTree, target: np.ndarray) -> float:
    forward = tree.query(points)[0]
    backward = cKDTree(points).query(target)[0]
    return 0.5 * float(forward.mean() + backward.mean())


def _similarity_for(points: np.ndarray, target: np.ndarray) -> tuple[float, np.ndarray]:
    """Scale matching the heights (Z extents) and translation matching the centroids of
    two sample sets."""
    height = np.ptp(points[:, 2])
    scale = float(np.ptp(target[:, 2]) / max(height, 1e-12))
    translation = target.mean(axis=0) - scale * points.mean(axis=0)
    return scale, translation


def align_bodies(source_vertices: np.ndarray, source_faces: np.ndarray,
                 target_vertices: np.ndarray, target_faces: np.ndarray,
                 refinements: int = 10) -> BodyAlignment:
    """The similarity transform of the source body onto the target (rest) body.

    Args:
        source_vertices, source_faces: ``(N_s, 3)``, ``(F_s, 3)`` any units, any
            axis-aligned orientation, T-pose.
        target_vertices, target_faces: the rest body (metres, Z up, facing −Y).
        refinements: scale + translation ICP steps after the turn is chosen.

    Raises:
        ValueError: a mesh without area, or a scale outside :data:`SCALE_RANGE`.
    """
    source, _ = surface_samples(source_vertices, source_faces, ALIGNMENT_SAMPLES)
    target, _ = surface_samples(target_vertices, target_faces, ALIGNMENT_SAMPLES, seed=1)
    tree = cKDTree(target)
    scored = []
    for turn in axis_turns():
        turned = source @ turn.T
        scale, translation = _similarity_for(turned, target)
        scored.append((_chamfer(scale * turned + translation, tree, target), turn, scale,
                       translation))
    scored.sort(key=lambda item: item[0])
    _, turn, scale, translation = scored[0]
    turned = source @ turn.T
    for _ in range(refinements):
        # Closest points in both directions, then the least-squares scale and
        # translation for those pairs (Umeyama without the rotation).
        moved = scale * turned + translation
        _, forward = tree.query(moved)
        _, backward = cKDTree(moved).query(target)
        a = np.concatenate([turned, turned[backward]])
        b = np.concatenate([target[forward], target])
        a_centre, b_centre = a.mean(axis=0), b.mean(axis=0)
        scale = float(np.sum((a - a_centre) * (b - b_centre)) / np.sum((a - a_centre) ** 2))
        translation = b_centre - scale * a_centre
    if not SCALE_RANGE[0] < scale < SCALE_RANGE[1]:
        raise ValueError(f"the source body would be scaled by {scale:.3g}: it is not a body")
    chamfer = _chamfer(scale * turned + translation, tree, target)
    return BodyAlignment(rotation=turn, scale=scale, translation=translation,
                         chamfer=chamfer, runner_up=float(scored[1][0]))


def _smoothing_operator(faces: np.ndarray, count: int) -> sp.csr_matrix:
    """Row-normalised ``(N, N)`` neighbour average with the vertex itself (isolated
    vertices keep their value)."""
    adjacency = adjacency_matrix(edge_index_from_faces(faces, count), count).astype(np.float64)
    adjacency = adjacency + sp.identity(count, format="csr")
    degree = np.asarray(adjacency.sum(axis=1)).ravel()
    return sp.diags(1.0 / degree) @ adjacency


def _smooth(values: np.ndarray, operator: sp.csr_matrix, steps: int) -> np.ndarray:
    for _ in range(steps):
        values = operator @ values
    return values


def register_bodies(source_vertices: np.ndarray, source_faces: np.ndarray,
                    target_vertices: np.ndarray, target_faces: np.ndarray,
                    iterations: int = 12, smoothing: tuple[int, int] = (60, 4),
                    normal_agreement: float = 0.3) -> np.ndarray:
    """Move the (aligned) source body onto the target body surface.

    Each iteration pairs every source vertex with its closest target vertex and every
    target vertex with its closest source vertex (pairs whose normals point apart —
    cosine below ``normal_agreement`` — are dropped), averages the displacements per
    source vertex, smooths them over the source mesh (``smoothing`` steps, from the
    first value down to the second over the iterations: first the overall proportions,
    then detail) and applies them.

    Shapes:
        source ``(N_s, 3)`` aligned (metres, the target's frame), ``(F_s, 3)``;
        target ``(N_t, 3)``, ``(F_t, 3)``; returns ``(N_s, 3)``.
    """
    current = np.array(source_vertices, dtype=np.float64)
    target = np.asarray(target_vertices, dtype=np.float64)
    target_normals = vertex_normals(target, target_faces)
    target_tree = cKDTree(target)
    operator = _smoothing_operator(source_faces, len(current))
    steps = np.geomspace(smoothing[0], smoothing[1], iterations).round().astype(int)
    for step in steps:
        normals = vertex_normals(current, source_faces)
        total = np.zeros_like(current)
        weight = np.zeros(len(current))
        _, forward = target_tree.query(current)
        agree = np.einsum("na,na->n", normals, target_normals[forward]) > normal_agreement
        total[agree] += target[forward[agree]] - current[agree]
        weight[agree] += 1.0
        _, backward = cKDTree(current).query(target)
        agree = np.einsum("na,na->n", normals[backward], target_normals) > normal_agreement
        np.add.at(total, backward[agree], target[agree] - current[backward[agree]])
        np.add.at(weight, backward[agree], 1.0)
        # Smooth the sum and the weight alike: vertices without a pair take their
        # neighbours' displacement instead of pulling the average towards zero.
        total = _smooth(total, operator, int(step))
        weight = _smooth(weight, operator, int(step))
        current += total / np.maximum(weight, 1e-9)[:, None] * (weight > 1e-6)[:, None]
    return current


def carry_garment(garment: np.ndarray, garment_faces: np.ndarray,
                  source_before: np.ndarray, source_after: np.ndarray,
                  neighbours: int = 8, smoothing: int = 10) -> np.ndarray:
    """Move a garment with its body's displacement field.

    Each garment vertex takes the mean displacement ``after − before`` of its
    ``neighbours`` closest source-body vertices, weighted by a Gaussian whose width is
    the closest distance (at least 1 cm, so a loose skirt hem averages over a patch, not
    one vertex), then the field is smoothed over the garment mesh.

    Shapes:
        garment ``(N, 3)``, garment_faces ``(F, 3)``; source_before/source_after
        ``(N_s, 3)`` (the aligned source body before and after registration); returns
        ``(N, 3)``.
    """
    garment = np.asarray(garment, dtype=np.float64)
    before = np.asarray(source_before, dtype=np.float64)
    displacement = np.asarray(source_after, dtype=np.float64) - before
    distance, index = cKDTree(before).query(garment, k=min(neighbours, len(before)))
    distance, index = distance.reshape(len(garment), -1), index.reshape(len(garment), -1)
    width = np.maximum(distance[:, :1], 0.01)
    weight = np.exp(-0.5 * (distance / width) ** 2)
    weight /= weight.sum(axis=1, keepdims=True)
    field = np.einsum("nk,nka->na", weight, displacement[index])
    field = _smooth(field, _smoothing_operator(garment_faces, len(garment)), smoothing)
    return garment + field


def fit_garment(garment: np.ndarray, garment_faces: np.ndarray,
                source_vertices: np.ndarray, source_faces: np.ndarray,
                target_vertices: np.ndarray, target_faces: np.ndarray) -> FittedGarment:
    """Align, register and carry: the garment made on the source body, on the target.

    Shapes:
        garment ``(N, 3)`` in the source body's frame and units; garment_faces
        ``(F, 3)``; source ``(N_s, 3)``/``(F_s, 3)``; target (the rest body, metres,
        Z up) ``(N_t, 3)``/``(F_t, 3)``.
    """
    alignment = align_bodies(source_vertices, source_faces, target_vertices, target_faces)
    aligned_body = alignment.apply(source_vertices)
    registered = register_bodies(aligned_body, source_faces, target_vertices, target_faces)
    pos = carry_garment(alignment.apply(garment), garment_faces, aligned_body, registered)
    samples, _ = surface_samples(target_vertices, target_faces, 20000)
    error = float(cKDTree(samples).query(registered)[0].mean())
    return FittedGarment(pos=pos, alignment=alignment, source_body=registered,
                         registration_error=error)
