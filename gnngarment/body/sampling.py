"""Deterministic Euclidean farthest-point sampling of body vertices."""

from __future__ import annotations

import numpy as np


def farthest_point_sampling(pos: np.ndarray, count: int, start: int = 0) -> np.ndarray:
    """Indices of ``count`` points chosen greedily, each farthest from those already chosen.

    Deterministic: the first index is ``start``; ties go to the lowest index.

    Shapes:
        pos ``(N, 3)`` → indices ``(count,)`` int64, distinct.

    Raises:
        ValueError: ``pos`` is not ``(N, 3)`` or ``count`` is not in ``[1, N]``.
    """
    pos = np.asarray(pos, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ValueError(f"pos must have shape (N, 3), got {pos.shape}")
    n = pos.shape[0]
    if not 1 <= count <= n:
        raise ValueError(f"count must be in [1, {n}], got {count}")
    if not 0 <= start < n:
        raise ValueError(f"start must be in [0, {n}), got {start}")
    chosen = np.empty(count, dtype=np.int64)
    chosen[0] = start
    distance = np.sum((pos - pos[start]) ** 2, axis=1)
    for k in range(1, count):
        index = int(np.argmax(distance))
        chosen[k] = index
        distance = np.minimum(distance, np.sum((pos - pos[index]) ** 2, axis=1))
    return chosen
