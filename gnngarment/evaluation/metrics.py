"""Per-frame error metrics of predicted garments (pure numpy).

Shapes: ``pred``/``target`` are ``(T, N, 3)`` garment vertices in metres, ``faces (F, 3)``,
``edges (E, 2)``. Every error function returns one value per frame ``(T,)`` so callers
can average over frames, sequences and garment types as they need; the skinning-weight
diagnostic :func:`far_joint_weight` summarises a whole sequence.
"""

from __future__ import annotations

import numpy as np

from gnngarment.geometry.normals import vertex_normals


def vertex_error(pred: np.ndarray, target: np.ndarray) -> np.ndarray:
    """E_verts: mean per-vertex Euclidean distance (metres) per frame."""
    return np.linalg.norm(pred - target, axis=-1).mean(-1)


def normal_error(pred: np.ndarray, target: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """E_norm: mean angle (degrees) between predicted and true area-weighted vertex
    normals, per frame."""
    cosine = (vertex_normals(pred, faces) * vertex_normals(target, faces)).sum(-1)
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))).mean(-1)


def hausdorff_distance(pred: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Symmetric Hausdorff distance between the predicted and true vertex sets
    (metres), per frame (KD-tree queries both ways)."""
    from scipy.spatial import cKDTree

    result = np.empty(len(pred))
    for t in range(len(pred)):
        forward = cKDTree(target[t]).query(pred[t])[0].max()
        backward = cKDTree(pred[t]).query(target[t])[0].max()
        result[t] = max(forward, backward)
    return result


def spatio_temporal_edge_difference(pred: np.ndarray, target: np.ndarray, edges: np.ndarray,
                                    rest: np.ndarray) -> np.ndarray:
    """STED (after Vasa & Skala 2011, as AnchorDEF reports it), simplified: the RMS over
    edges of the difference in relative edge length ``l / l_rest`` (spatial part),
    combined with the RMS difference of its frame-to-frame change (temporal part) as
    ``sqrt(s² + t²)``. Unitless, per frame (the temporal part is 0 at frame 0).

    Shapes: pred/target ``(T, N, 3)``, edges ``(E, 2)``, rest ``(N, 3)``.
    """
    rest_length = np.linalg.norm(rest[edges[:, 0]] - rest[edges[:, 1]], axis=-1)

    def relative(pos: np.ndarray) -> np.ndarray:
        return np.linalg.norm(pos[:, edges[:, 0]] - pos[:, edges[:, 1]], axis=-1) / rest_length

    difference = relative(pred) - relative(target)                     # (T, E)
    spatial = np.sqrt((difference**2).mean(-1))
    temporal = np.zeros(len(pred))
    temporal[1:] = np.sqrt((np.diff(difference, axis=0) ** 2).mean(-1))
    return np.sqrt(spatial**2 + temporal**2)


def collision_rate(pred: np.ndarray, body_points: np.ndarray, body_normals: np.ndarray
                   ) -> np.ndarray:
    """Percentage of garment vertices inside the body per frame: the offset to the
    nearest body sample along its outward normal is negative.

    Shapes: pred ``(T, N, 3)``, body_points/body_normals ``(T, M, 3)``.
    """
    from scipy.spatial import cKDTree

    rates = np.empty(len(pred))
    for t in range(len(pred)):
        _, nearest = cKDTree(body_points[t]).query(pred[t])
        offset = ((pred[t] - body_points[t][nearest]) * body_normals[t][nearest]).sum(-1)
        rates[t] = 100.0 * (offset < 0).mean()
    return rates


def mesh_collision_rate(pred: np.ndarray, body_vertices: np.ndarray,
                        body_faces: np.ndarray) -> np.ndarray:
    """Percentage of garment vertices inside the posed body **mesh** per frame: its
    winding number there is at least 1 (warp's BVH ray casts, as collision resolution
    tests it). :func:`collision_rate`'s nearest-sample normal misjudges vertices a few
    millimetres outside concave regions (armpits, crotch) as inside; this does not. The
    winding number counts a vertex where two body parts overlap (winding 2: an arm sunk
    into the chest) as inside, where a ray's crossing parity (the measure before
    2026-12-07) counted it outside.

    Shapes: pred ``(T, N, 3)``, body_vertices ``(T, N_b, 3)``, body_faces ``(F_b, 3)``.
    """
    from gnngarment.geometry.signed_distance import refit_mesh, warp_mesh, winding_numbers

    mesh = warp_mesh(body_vertices[0], body_faces)
    rates = np.empty(len(pred))
    for t in range(len(pred)):
        if t:
            refit_mesh(mesh, body_vertices[t])
        rates[t] = 100.0 * (winding_numbers(mesh, pred[t]) >= 1).mean()
    return rates


def far_joint_weight(weights: np.ndarray, rest_pos: np.ndarray, body_rest_vertices: np.ndarray,
                     body_skinning_weights: np.ndarray, radius: float = 0.20
                     ) -> dict[str, float]:
    """Skinning weight a garment puts on joints whose body part is far away: for each
    vertex, the summed weight on the joints whose body region lies more than ``radius``
    from the vertex's rest position. A joint's region is the body vertices it moves
    noticeably (skinning weight ≥ ``REGION_WEIGHT``); its distance is that of the
    region's nearest vertex, counted from the vertex's nearest body vertex (so a hem
    hanging 25 cm off the legs is not "far" from the legs). A joint that moves no body
    vertex counts as far (:func:`~gnngarment.body.joint_reach.joint_region_distances`,
    the distance the model's weight reach masks by). Such weight makes the vertex follow
    a distant limb (a hem dragged along by a wrist).
    (Regions by *dominant* joint were tried first and are wrong: Anny's pelvis dominates
    no vertex, so a skirt skinned to the pelvis counted as 100 % far.)

    Shapes:
        weights ``(T, N, 24)`` or ``(N, 24)`` garment skinning weights, rest_pos
        ``(N, 3)`` (metres), body_rest_vertices ``(N_b, 3)`` (same rest frame),
        body_skinning_weights ``(N_b, 24)``; ``radius`` in metres.

    Returns:
        ``{"max": ..., "mean": ...}``: the largest and the mean far weight over vertices
        and frames, as fractions of each vertex's unit weight (0 = none, 1 = all).
    """
    from gnngarment.body.joint_reach import joint_region_distances

    weights = np.asarray(weights)
    if weights.ndim == 2:
        weights = weights[None]
    joints = body_skinning_weights.shape[1]
    if weights.ndim != 3 or weights.shape[1:] != (len(rest_pos), joints):
        raise ValueError(f"weights must be (T, {len(rest_pos)}, {joints}) or "
                         f"({len(rest_pos)}, {joints}), got {weights.shape}")
    distance = joint_region_distances(rest_pos, body_rest_vertices, body_skinning_weights)
    far = (weights * (distance > radius)[None]).sum(-1)                  # (T, N)
    return {"max": float(far.max()), "mean": float(far.mean())}
