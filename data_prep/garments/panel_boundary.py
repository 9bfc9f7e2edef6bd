"""One panel's outline in the pattern plane, split into seam and opening runs.

Each boundary stretch of a panel's Ω (:mod:`.silhouette`) is a *seam* (shared by both
panels, where the solid itself bounds Ω) or an *opening* (where a cut does: hem, cuffs,
neck, waist, armholes; one copy per panel).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from data_prep.garments.errors import PatternError
from data_prep.garments.shapes import Design
from data_prep.garments.silhouette import Silhouette, region_terms


@dataclasses.dataclass
class PanelBoundary:
    """One panel's boundary as runs: each run is a polyline ``(n, 2)`` from corner to
    corner (consecutive runs share their end points), counter-clockwise in (X, Z), with
    ``label`` 0 for a seam or ``k`` for the opening made by cut ``k − 1``."""

    runs: list[np.ndarray]
    labels: list[int]


def trace(design: Design, sil: Silhouette, side: int) -> PanelBoundary:
    """Trace one panel's Ω and split its boundary into seam and opening runs.

    Raises:
        PatternError: if Ω is not one region without holes, or has no opening.
    """
    import contourpy

    lines = contourpy.contour_generator(sil.x, sil.z, sil.region[side]).lines(0.0)
    loops = [line for line in lines if len(line) > 3 and np.allclose(line[0], line[-1])]
    if len(loops) < len(lines):
        raise PatternError("the garment region reaches the edge of its box")
    if not loops:
        raise PatternError("the garment region is empty")

    def area(loop: np.ndarray) -> float:
        return 0.5 * float(np.sum(loop[:-1, 0] * loop[1:, 1] - loop[1:, 0] * loop[:-1, 1]))

    areas = np.array([area(loop) for loop in loops])
    main = int(np.argmax(np.abs(areas)))
    others = np.abs(np.delete(areas, main))
    if (others > 4 * float(sil.x[1] - sil.x[0]) ** 2).any():
        raise PatternError(f"the garment region is not one simple piece ({len(loops)} outlines)")
    loop = loops[main][:-1]
    if areas[main] < 0:  # counter-clockwise in (x, z)
        loop = loop[::-1]
    label = region_terms(design, sil, loop, side).argmax(axis=1)
    # Drop label flicker: a run of under 3 points between two runs of one label.
    for _ in range(3):
        changes = np.flatnonzero(label != np.roll(label, 1))
        if len(changes) < 2:
            break
        for start, end in zip(changes, np.roll(changes, -1), strict=True):
            length = (end - start) % len(label)
            if 0 < length < 3 and label[start - 1] == label[end % len(label)]:
                label[np.arange(start, start + length) % len(label)] = label[start - 1]
    changes = np.flatnonzero(label != np.roll(label, 1))
    if len(changes) == 0:
        raise PatternError("the garment has no opening")
    runs, labels = [], []
    for start, end in zip(changes, np.roll(changes, -1), strict=True):
        length = (end - start) % len(loop) or len(loop)
        idx = np.arange(start, start + length + 1) % len(loop)
        run = loop[idx].copy()
        # Corners halfway between the last point of a run and the first of the next.
        run[0] = (loop[start] + loop[start - 1]) / 2
        run[-1] = (loop[end % len(loop)] + loop[end - 1]) / 2
        runs.append(run)
        labels.append(int(label[start]))
    for label_, following in zip(labels, labels[1:] + labels[:1], strict=True):
        if label_ != 0 and following != 0:
            raise PatternError("two openings touch (e.g. a neckline reaching an armhole)")
    return PanelBoundary(runs=runs, labels=labels)
