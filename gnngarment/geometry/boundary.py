"""A mesh's boundary: its loops of open edges, and the one that holds a garment up.

Pure numpy, no torch.
"""

from __future__ import annotations

import numpy as np

#: The largest gap (radians) in the angles of a loop's points around the body's axis for
#: the loop to count as going around the body (a waistband, not an armhole or a strap).
MAX_ANGULAR_GAP = np.radians(60.0)
#: Body vertices within this height (metres) of a loop give the body's axis there.
AXIS_SLAB = 0.03


def boundary_loops(faces: np.ndarray) -> list[np.ndarray]:
    """Boundary loops of a manifold triangle mesh, each ``(L,)`` vertex indices in order
    (following the faces' winding).

    Raises:
        ValueError: a boundary vertex is on two loops (a non-manifold vertex).
    """
    faces = np.asarray(faces, dtype=np.int64)
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    n = int(faces.max()) + 1
    keys = directed[:, 0] * n + directed[:, 1]
    reverse = directed[:, 1] * n + directed[:, 0]
    border = directed[~np.isin(keys, reverse)]
    following = dict(zip(border[:, 0].tolist(), border[:, 1].tolist(), strict=True))
    if len(following) != len(border):
        raise ValueError("a boundary vertex is on two boundary loops (non-manifold vertex)")
    loops, seen = [], set()
    for start in border[:, 0].tolist():
        if start in seen:
            continue
        loop, v = [], start
        while v not in seen:
            seen.add(v)
            loop.append(v)
            v = following[v]
        loops.append(np.array(loop, dtype=np.int64))
    return loops


def support_band(pos: np.ndarray, faces: np.ndarray, body_vertices: np.ndarray
                 ) -> np.ndarray:
    """The vertices of the garment's highest boundary loop if it goes around the body:
    the waistband of a skirt or trousers, the top band of a strapless dress, a
    T-shirt's neckline. A drape holds them where they are — without them a skirt whose
    waist is wider than the hips slides to the floor.

    Args:
        pos: ``(N, 3)`` garment vertices, metres, Z up; faces ``(F, 3)``.
        body_vertices: ``(N_b, 3)`` the body the garment is on.

    Returns:
        ``(L,)`` vertex indices; empty when no loop goes around the body (a closed mesh,
        a garment whose highest opening is an armhole or a strap) or the mesh's boundary
        is not manifold.
    """
    pos, body = np.asarray(pos, dtype=np.float64), np.asarray(body_vertices, np.float64)
    try:
        loops = boundary_loops(faces)
    except ValueError:
        return np.zeros(0, dtype=np.int64)
    if not loops:
        return np.zeros(0, dtype=np.int64)
    top = max(loops, key=lambda loop: pos[loop, 2].mean())
    height = pos[top, 2].mean()
    slab = body[np.abs(body[:, 2] - height) < AXIS_SLAB]
    if len(slab) == 0:
        return np.zeros(0, dtype=np.int64)
    # The axis of the body part the loop is around: the slab's points nearest the loop
    # (at the hips of a T-posed body the slab also cuts the hands).
    centre = pos[top, :2].mean(axis=0)
    near = slab[np.linalg.norm(slab[:, :2] - centre, axis=1)
                < 1.5 * np.linalg.norm(pos[top, :2] - centre, axis=1).max()]
    axis = near[:, :2].mean(axis=0) if len(near) else centre
    angles = np.sort(np.arctan2(*(pos[top, :2] - axis).T[::-1]))
    gaps = np.diff(np.concatenate([angles, angles[:1] + 2 * np.pi]))
    return top if gaps.max() <= MAX_ANGULAR_GAP else np.zeros(0, dtype=np.int64)
