"""Garment linear blend skinning with the 24 canonical joint transforms."""

from __future__ import annotations

import torch

from gnngarment.body.skeleton import NUM_JOINTS


def skin(
    rest_vertices: torch.Tensor,
    blend_shapes: torch.Tensor | None,
    weights: torch.Tensor,
    joint_transforms: torch.Tensor,
    batch: torch.Tensor | None = None,
) -> torch.Tensor:
    """Linear blend skinning ``x_i = Σ_j w_ij G_j [r_i + b_i; 1]`` (differentiable).

    ``G_j`` are skinning transforms (rest world → posed world, see
    :mod:`gnngarment.body.skeleton`); weights are used as given (the caller normalises
    them, e.g. by a softmax over joints).

    Two layouts, as in PyG:

    * **dense** (``batch is None``): ``rest_vertices (B, N, 3)``, ``blend_shapes (B, N, 3)``,
      ``weights (B, N, 24)``, ``joint_transforms (B, 24, 4, 4)`` → ``(B, N, 3)``. Leading
      dimensions broadcast (e.g. one garment ``(N, 3)`` against ``(T, 24, 4, 4)`` frames
      gives ``(T, N, 3)``).
    * **ragged** (``batch (N,)`` given): garments of different sizes concatenated along the
      vertex axis: ``rest_vertices (N, 3)``, ``blend_shapes (N, 3)``, ``weights (N, 24)``,
      ``joint_transforms (B, 24, 4, 4)``, vertex ``i`` uses ``joint_transforms[batch[i]]``
      → ``(N, 3)``.

    Args:
        rest_vertices: rest positions, metres.
        blend_shapes: per-vertex offsets added in the rest pose, or ``None`` for zero.
        weights: skinning weights over the 24 joints.
        joint_transforms: 4×4 skinning transforms.
        batch: garment index of each vertex (ragged layout only).

    Returns:
        Posed vertices.
    """
    if rest_vertices.shape[-1] != 3:
        raise ValueError(f"rest_vertices must be (..., N, 3), got {tuple(rest_vertices.shape)}")
    if weights.shape[-1] != NUM_JOINTS:
        raise ValueError(f"weights must be (..., N, {NUM_JOINTS}), got {tuple(weights.shape)}")
    if joint_transforms.shape[-3:] != (NUM_JOINTS, 4, 4):
        raise ValueError(
            f"joint_transforms must be (..., {NUM_JOINTS}, 4, 4), "
            f"got {tuple(joint_transforms.shape)}"
        )
    points = rest_vertices if blend_shapes is None else rest_vertices + blend_shapes
    affine = joint_transforms[..., :3, :]  # (..., 24, 3, 4)
    if batch is not None:
        if rest_vertices.dim() != 2 or weights.dim() != 2 or batch.dim() != 1:
            raise ValueError(
                "with a batch vector, rest_vertices must be (N, 3), weights (N, 24), batch (N,)"
            )
        if not (rest_vertices.shape[0] == weights.shape[0] == batch.shape[0]):
            raise ValueError(
                f"vertex counts differ: rest_vertices {rest_vertices.shape[0]}, "
                f"weights {weights.shape[0]}, batch {batch.shape[0]}"
            )
        if joint_transforms.dim() != 4:
            raise ValueError("with a batch vector, joint_transforms must be (B, 24, 4, 4)")
        blended = _blend_ragged(weights, affine.reshape(-1, NUM_JOINTS, 12), batch)
    else:
        if weights.shape[:-1] != rest_vertices.shape[:-1] and weights.dim() == rest_vertices.dim():
            raise ValueError(
                f"weights {tuple(weights.shape)} do not match rest_vertices "
                f"{tuple(rest_vertices.shape)}"
            )
        # (..., N, 24) × (..., 24, 3, 4) → (..., N, 3, 4), leading dimensions broadcast.
        flat = affine.reshape(*affine.shape[:-3], NUM_JOINTS, 12)
        product = torch.matmul(weights, flat)  # (..., N, 12), broadcast over leading dims
        blended = product.reshape(*product.shape[:-1], 3, 4)
    # x = A p + t per vertex, elementwise: a batched matmul of 3x3 blocks is ~10x slower.
    return (blended[..., :3] * points[..., None, :]).sum(-1) + blended[..., 3]


def _blend_ragged(weights: torch.Tensor, flat: torch.Tensor, batch: torch.Tensor
                  ) -> torch.Tensor:
    """Per-vertex blended transforms ``(N, 3, 4)`` of the ragged layout: ``weights
    (N, 24)`` against ``flat (B, 24, 12)``, vertex ``i`` using item ``batch[i]``.

    With the items' vertices in contiguous runs (PyG's batch layout, and every batch the
    model builds) each item is one ``(n_b, 24) @ (24, 12)`` product. Gathering the
    transforms per vertex instead materialises ``N × 24 × 12`` floats (92 MB for 16 frames
    of a 5,000-vertex garment) and took 14 % of the forward pass.
    """
    if len(batch) > 1 and bool((batch[1:] < batch[:-1]).any()):  # not in runs: gather
        return torch.einsum("nj,njk->nk", weights, flat[batch]).view(-1, 3, 4)
    counts = torch.bincount(batch, minlength=flat.shape[0]).tolist()
    parts = [part @ flat[item] for item, part in enumerate(torch.split(weights, counts))]
    return torch.cat(parts).view(-1, 3, 4)
