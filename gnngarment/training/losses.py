"""Loss terms of the two training stages (blueprint Sec. 3.4, DESIGN.md "Losses").

Every term is a pure function of tensors, averaged so that its scale does not depend on
the garment's resolution; the weights (k_v, k_e, ...) live in the training config.

Shapes used throughout: ``pred``/``target``/``rest`` are ``(V, 3)`` vertices (metres)
of a batch of garments, ``edges (2, E)`` and ``faces (F, 3)`` index them.
"""

from __future__ import annotations

import numpy as np
import torch

#: Standard gravity (m/s²), along −Z (the library's up axis is +Z).
GRAVITY = 9.81


def vertex_loss(pred: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Mean squared vertex distance (m²)."""
    return ((pred - target) ** 2).sum(-1).mean()


def blend_shape_loss(blend_shapes: torch.Tensor) -> torch.Tensor:
    """Mean squared blend shape (m²): zero for plain skinning of the template."""
    return (blend_shapes ** 2).sum(-1).mean()


def edge_lengths(pos: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
    """``(E,)`` lengths of the edges ``(2, E)``."""
    return (pos[edges[0]] - pos[edges[1]]).norm(dim=-1)


def edge_loss(pred: torch.Tensor, target: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
    """Mean squared edge-length difference (m²)."""
    return ((edge_lengths(pred, edges) - edge_lengths(target, edges)) ** 2).mean()


def face_normals(pos: torch.Tensor, faces: torch.Tensor) -> torch.Tensor:
    """``(F, 3)`` unit face normals."""
    a, b, c = pos[faces[:, 0]], pos[faces[:, 1]], pos[faces[:, 2]]
    return torch.nn.functional.normalize(torch.cross(b - a, c - a, dim=-1), dim=-1, eps=1e-12)


def normal_loss(pred: torch.Tensor, target: torch.Tensor, faces: torch.Tensor) -> torch.Tensor:
    """Mean ``1 − n·n̂`` over faces (0 when every face keeps its orientation)."""
    return (1 - (face_normals(pred, faces) * face_normals(target, faces)).sum(-1)).mean()


def nearest_body_points(pos: torch.Tensor, body: torch.Tensor, item: torch.Tensor,
                        body_item: torch.Tensor) -> torch.Tensor:
    """Index of the nearest body point of the same item for every garment vertex.

    A KD-tree per item (scipy): no gradient is needed through the *choice* of nearest
    point, only through the distance to it.

    Shapes:
        pos ``(V, 3)``, body ``(M, 3)``, item ``(V,)``, body_item ``(M,)`` → ``(V,)`` long.
    """
    from scipy.spatial import cKDTree

    positions = pos.detach().cpu().numpy()
    body_points = body.detach().cpu().numpy()
    items, body_items = item.cpu().numpy(), body_item.cpu().numpy()
    nearest = np.empty(len(positions), dtype=np.int64)
    body_order = np.argsort(body_items, kind="stable")
    body_bounds = np.searchsorted(body_items[body_order], np.arange(items.max() + 2))
    for k in np.unique(items):
        members = np.flatnonzero(items == k)
        candidates = body_order[body_bounds[k]:body_bounds[k + 1]]
        _, local = cKDTree(body_points[candidates]).query(positions[members])
        nearest[members] = candidates[local]
    return torch.from_numpy(nearest).to(pos.device)


def signed_distance(pos: torch.Tensor, body: torch.Tensor, body_normals: torch.Tensor,
                    item: torch.Tensor, body_item: torch.Tensor) -> torch.Tensor:
    """Approximate signed distance to the posed body (m): the offset from the nearest
    body point along that point's outward normal (negative inside), as HOOD and SNUG
    use for collisions.

    Shapes:
        pos ``(V, 3)``; body, body_normals ``(M, 3)``; item ``(V,)``; body_item ``(M,)``
        → ``(V,)``.
    """
    nearest = nearest_body_points(pos, body, item, body_item)
    return ((pos - body[nearest]) * body_normals[nearest]).sum(-1)


def collision_loss(pos: torch.Tensor, body: torch.Tensor, body_normals: torch.Tensor,
                   item: torch.Tensor, body_item: torch.Tensor,
                   margin: float = 0.004) -> torch.Tensor:
    """Mean ``|min(h(x) − ε, 0)|``: penetration depth below the margin ``ε`` (m)."""
    depth = signed_distance(pos, body, body_normals, item, body_item) - margin
    return torch.clamp(depth, max=0).abs().mean()


def gravity_loss(pos: torch.Tensor, reference: torch.Tensor, vertex_mass: torch.Tensor,
                 num_garments: int = 1) -> torch.Tensor:
    """Gravitational potential energy relative to ``reference`` heights, per garment
    (joules): ``Σ_i m_i g (z_i − z_ref,i) / num_garments``. Mass-weighted so the pull
    on a vertex is its weight, independent of the mesh resolution.

    Shapes:
        pos, reference ``(V, 3)`` metres; vertex_mass ``(V,)`` kg.
    """
    return GRAVITY * (vertex_mass * (pos[:, 2] - reference[:, 2])).sum() / num_garments


def green_strain(pos: torch.Tensor, faces: torch.Tensor, rest_inverse: torch.Tensor
                 ) -> torch.Tensor:
    """Green–Lagrange strain ``E = ½ (FᵀF − I)`` per triangle, ``(F, 2, 2)``.

    ``rest_inverse (F, 2, 2)`` comes from
    :func:`gnngarment.geometry.triangle_frames.rest_triangle_frames`.
    """
    a, b, c = pos[faces[:, 0]], pos[faces[:, 1]], pos[faces[:, 2]]
    deformed = torch.stack([b - a, c - a], dim=-1)            # (F, 3, 2)
    gradient = deformed @ rest_inverse.to(pos.dtype)            # (F, 3, 2)
    identity = torch.eye(2, dtype=pos.dtype, device=pos.device)
    return 0.5 * (gradient.transpose(-1, -2) @ gradient - identity)


def stretch_loss(pos: torch.Tensor, faces: torch.Tensor, rest_inverse: torch.Tensor,
                 rest_area: torch.Tensor) -> torch.Tensor:
    """Area-weighted mean of ``E_uu² + E_vv²`` (stretch along the rest frame axes)."""
    strain = green_strain(pos, faces, rest_inverse)
    energy = strain[:, 0, 0] ** 2 + strain[:, 1, 1] ** 2
    return (energy * rest_area).sum() / rest_area.sum()


def shear_loss(pos: torch.Tensor, faces: torch.Tensor, rest_inverse: torch.Tensor,
               rest_area: torch.Tensor) -> torch.Tensor:
    """Area-weighted mean of ``E_uv²`` (in-plane shear)."""
    strain = green_strain(pos, faces, rest_inverse)
    return ((strain[:, 0, 1] ** 2) * rest_area).sum() / rest_area.sum()
