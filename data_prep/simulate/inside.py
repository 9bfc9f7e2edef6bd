"""Signed distance of points to a closed triangle mesh (inside/outside of the body).

Runs on every simulated frame, so it is a small Warp kernel over Warp's mesh BVH:
closest-point query plus ray-crossing parity for the sign
(``wp.mesh_query_point_sign_parity``), correct for closed meshes like the posed body.
On 3,000 points around the walking Anny body it agreed with an exact winding number on
every point; the closest-face-normal sign (``mesh_query_point_sign_normal``, 2× faster)
got two points between the toes wrong (docs/simulation.md).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from data_prep.simulate._backend import import_warp

#: Closest-point search radius [m]; points farther from the body count as outside
#: (no garment vertex lies more than this deep inside a human body).
SEARCH_RADIUS = 1.0


@functools.lru_cache(maxsize=1)
def _signed_distance_kernel() -> Any:
    """The Warp kernel, defined on first use (Warp is imported lazily)."""
    wp = import_warp()

    @wp.kernel
    def signed_distance(mesh: wp.uint64, points: wp.array(dtype=wp.vec3),
                        max_dist: float, out: wp.array(dtype=float)):
        tid = wp.tid()
        query = wp.mesh_query_point_sign_parity(mesh, points[tid], max_dist)
        if query.result:
            closest = wp.mesh_eval_position(mesh, query.face, query.u, query.v)
            out[tid] = query.sign * wp.length(points[tid] - closest)
        else:
            out[tid] = max_dist

    return signed_distance


def signed_distance_warp(mesh: Any, points: np.ndarray) -> np.ndarray:
    """Signed distance of ``points`` to an existing ``warp.Mesh`` (refit if it moved).

    Args:
        mesh: a ``warp.Mesh`` on the CPU.
        points: ``(N, 3)`` [m].

    Returns:
        ``(N,)`` float32 [m], negative inside, capped at :data:`SEARCH_RADIUS`.
    """
    wp = import_warp()
    kernel = _signed_distance_kernel()
    points_wp = wp.array(np.ascontiguousarray(points, dtype=np.float32), dtype=wp.vec3,
                         device="cpu")
    out = wp.empty(len(points), dtype=float, device="cpu")
    wp.launch(kernel, dim=len(points), inputs=[mesh.id, points_wp, SEARCH_RADIUS, out],
              device="cpu")
    return out.numpy().copy()


def signed_distance(points: np.ndarray, vertices: np.ndarray,
                    faces: np.ndarray) -> np.ndarray:
    """Signed distance of ``points`` to the closed mesh (``vertices``, ``faces``).

    Args:
        points: ``(N, 3)`` [m].
        vertices: ``(V, 3)`` [m]; faces ``(F, 3)`` int, outward winding.

    Returns:
        ``(N,)`` float32 [m], negative inside.
    """
    wp = import_warp()
    mesh = wp.Mesh(points=wp.array(np.ascontiguousarray(vertices, dtype=np.float32),
                                   dtype=wp.vec3, device="cpu"),
                   indices=wp.array(np.ascontiguousarray(faces, dtype=np.int32).ravel(),
                                    dtype=wp.int32, device="cpu"))
    return signed_distance_warp(mesh, points)
