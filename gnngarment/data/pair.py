"""The model's per garment–body pair input (the data contract between cache and model)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from gnngarment.geometry.hierarchy import PoolHierarchy


@dataclass
class GarmentBodyPair:
    """Model inputs of one garment on one body (tensors; built by the data layer).

    Attributes:
        rest_pos: ``(N, 3)`` garment rest positions on the rest body (metres).
        features: ``(N, 30)`` vertex features (:func:`garment_vertex_features`).
        hierarchy: the garment's pooling hierarchy (topology only).
        descriptor: ``(N*,)`` Nyström style descriptor.
        body_distances: ``(N_b', 24)`` body-shape feature ``D``.
        body_weights: ``(N, 24)`` the body's skinning weights transferred to the garment's
            rest vertices (rows sum to 1; ``transfer_body_weights``): the ``body`` weight
            prior's starting point. ``None`` where unknown (models with prior ``none``).
        joint_distances: ``(N, 24)`` how far (metres) each joint's body region lies from
            each rest vertex beyond the body's nearest point
            (:func:`~gnngarment.body.joint_reach.joint_region_distances`): the weight
            reach's mask. ``None`` where unknown (models without a ``weight_reach``).
    """

    rest_pos: torch.Tensor
    features: torch.Tensor
    hierarchy: PoolHierarchy
    descriptor: torch.Tensor
    body_distances: torch.Tensor
    body_weights: torch.Tensor | None = None
    joint_distances: torch.Tensor | None = None

    @classmethod
    def from_arrays(cls, rest_pos: np.ndarray, features: np.ndarray, hierarchy: PoolHierarchy,
                    descriptor: np.ndarray, body_distances: np.ndarray,
                    body_weights: np.ndarray | None = None,
                    joint_distances: np.ndarray | None = None) -> GarmentBodyPair:
        """The pair from numpy arrays (any float dtype; each becomes a float32 tensor),
        with the shapes of the attributes above: the one place the data layer, ``animate``
        and the benchmarks turn arrays into the model's input."""
        def tensor(values: np.ndarray) -> torch.Tensor:
            return torch.from_numpy(np.asarray(values, dtype=np.float32))

        return cls(rest_pos=tensor(rest_pos), features=tensor(features), hierarchy=hierarchy,
                   descriptor=tensor(descriptor), body_distances=tensor(body_distances),
                   body_weights=None if body_weights is None else tensor(body_weights),
                   joint_distances=(None if joint_distances is None
                                    else tensor(joint_distances)))
