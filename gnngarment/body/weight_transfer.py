"""Skinning weights carried from a body to a garment on it: the body-skinning baseline,
the model's weight prior and the pin weights of the dataset builder all use them."""

from __future__ import annotations

import numpy as np


def transfer_body_weights(garment_pos: np.ndarray, body_vertices: np.ndarray,
                          body_weights: np.ndarray, neighbours: int = 4) -> np.ndarray:
    """Body-skinning baseline weights: every garment vertex takes the inverse-distance
    weighted mean of the skinning weights of its ``neighbours`` nearest rest-body
    vertices (the classic "skin the garment like the body" approach, no blend shapes).

    Shapes:
        garment_pos ``(N, 3)``, body_vertices ``(N_b, 3)`` (rest, same frame),
        body_weights ``(N_b, 24)`` → ``(N, 24)``, rows sum to 1.
    """
    from scipy.spatial import cKDTree

    distance, index = cKDTree(body_vertices).query(garment_pos, k=neighbours)
    distance = distance.reshape(len(garment_pos), -1)
    index = index.reshape(len(garment_pos), -1)
    inverse = 1.0 / np.maximum(distance, 1e-6)
    inverse /= inverse.sum(1, keepdims=True)
    weights = (body_weights[index] * inverse[..., None]).sum(1)
    return (weights / weights.sum(1, keepdims=True)).astype(np.float32)
