"""Whether a simulated garment is still worn: the drape and sequence workers leave out a
garment that slid off or fell down the body (the simulator's gates - NaN, stretch,
penetration - do not see a garment falling)."""

from __future__ import annotations

import numpy as np

#: A garment whose mean distance to the body exceeds this in any frame has slid off.
MAX_MEAN_BODY_DISTANCE = 0.15
#: The largest mean downward slide (metres) of the garment relative to the body before a
#: simulated sequence counts as "fell off": a strapless jumpsuit that slid to the feet
#: stays close to the body's shins, so the distance test alone passes it.
MAX_MEAN_DROP = 0.15


def left_the_body(positions: np.ndarray, body_points: np.ndarray,
                  limit: float = MAX_MEAN_BODY_DISTANCE, rest: np.ndarray | None = None,
                  max_drop: float = MAX_MEAN_DROP) -> str:
    """Why a simulated garment is not worn any more, or ``""``: its vertices are on
    average further than ``limit`` from the body, or (given its ``rest`` positions on
    the rest body, which frame 0's body pose starts from) they slid down by more than
    ``max_drop`` on average, beyond the body's own vertical motion.

    Shapes: positions ``(T, N, 3)``, body_points ``(T, M, 3)``, rest ``(N, 3)`` (metres).
    """
    from scipy.spatial import cKDTree

    # The body points under the garment at rest: how far *they* move up or down is the
    # body's own motion (a squat lowers the torso, not the feet).
    if rest is not None:
        under = cKDTree(body_points[0]).query(rest)[1]
        under_height = body_points[:, under, 2].mean(axis=1)   # (T,)
        rest_height = float(rest[:, 2].mean())
    for t in range(len(positions)):
        distance = float(cKDTree(body_points[t]).query(positions[t])[0].mean())
        if distance > limit:
            return (f"garment slid off the body: mean distance {distance:.2f} m > {limit} m "
                    f"at frame {t}")
        if rest is not None:
            body_rise = float(under_height[t] - under_height[0])
            drop = rest_height - float(positions[t, :, 2].mean()) + body_rise
            if drop > max_drop:
                return (f"garment fell down the body: mean drop {drop:.2f} m > {max_drop} m "
                        f"at frame {t}")
    return ""
