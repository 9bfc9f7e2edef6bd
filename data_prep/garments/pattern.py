"""A garment's sewing pattern: front and back panels in the frontal (X, Z) plane.

The garment is a *front* and a *back* panel of the shape Ω it has seen from the front
(:mod:`.silhouette`), sewn together along the seams and left open along the cuts (hem,
cuffs, neck, waist, armholes). Each panel's outline is traced into seam and opening
runs (:mod:`.panel_boundary`) and the two are paired here so that they share their
seams. Both panels are then triangulated with the same seam points but different
random interior points (:mod:`.panel_triangulation`) and stitched along the seams
(:mod:`.stitching`), so the result is a manifold by construction: every seam edge has
one front and one back triangle, and each opening becomes one closed boundary loop
(front half + back half).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from data_prep.garments.errors import PatternError
from data_prep.garments.panel_boundary import PanelBoundary


@dataclasses.dataclass
class Pattern:
    """Front and back panels sharing their seams.

    ``order`` is the cyclic sequence of runs, the same for both panels: ``(0, i)`` is the
    shared seam run ``seams[i]``, ``(k, i)`` (k >= 1) is opening run ``i`` made by cut
    ``k − 1``, drawn as ``openings[side][i]`` on each panel (side −1 front, +1 back).
    """

    seams: list[np.ndarray]
    openings: dict[int, list[np.ndarray]]
    order: list[tuple[int, int]]

    def boundary(self, side: int) -> list[np.ndarray]:
        """That panel's runs in order (each from corner to corner)."""
        return [self.seams[i] if k == 0 else self.openings[side][i] for k, i in self.order]


def pair(front: PanelBoundary, back: PanelBoundary) -> Pattern:
    """Align the back outline with the front one and make their seams identical (the
    front's), snapping the back openings' ends onto the shared corners.

    Raises:
        PatternError: if the two panels do not have the same sequence of runs.
    """
    if len(front.runs) != len(back.runs) or sorted(front.labels) != sorted(back.labels):
        raise PatternError("front and back panels have different openings")
    count = len(front.runs)
    first_seam = front.labels.index(0)
    start = front.runs[first_seam][0]
    candidates = [i for i in range(count) if back.labels[i] == 0]
    shift = min(candidates, key=lambda i: float(np.linalg.norm(back.runs[i][0] - start)))
    shift = (shift - first_seam) % count
    back_runs = back.runs[shift:] + back.runs[:shift]
    back_labels = back.labels[shift:] + back.labels[:shift]
    if back_labels != front.labels:
        raise PatternError("front and back panels have different openings")
    seams, openings, order = [], {-1: [], 1: []}, []
    for i, label in enumerate(front.labels):
        if label == 0:
            order.append((0, len(seams)))
            seams.append(front.runs[i])
        else:
            before, after = front.runs[i - 1], front.runs[(i + 1) % count]
            back_run = back_runs[i].copy()
            back_run[0], back_run[-1] = before[-1], after[0]
            order.append((label, len(openings[-1])))
            openings[-1].append(front.runs[i])
            openings[1].append(back_run)
    return Pattern(seams=seams, openings=openings, order=order)


def resample(polyline: np.ndarray, lengths: np.ndarray, spacing: float) -> np.ndarray:
    """Points along ``polyline (n, 2)`` equally spaced in the arc length measured by
    ``lengths (n − 1,)`` (the 3D lengths of its segments), both ends kept."""
    arc = np.concatenate([[0.0], np.cumsum(lengths)])
    count = max(round(float(arc[-1] / spacing)), 1)
    targets = np.linspace(0.0, arc[-1], count + 1)
    return np.stack([np.interp(targets, arc, polyline[:, k]) for k in range(2)], axis=1)
