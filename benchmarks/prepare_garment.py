"""Time per-garment preparation (2-level pooling hierarchy + Nyström descriptor).

Two mesh families at ~1k, 5k, 20k and 50k vertices:
- ``skirt``: an irregular Delaunay triangulation of a flared skirt (a conical annulus),
  valences and eccentricities as uneven as in garments exported from a DCC tool;
- ``tube``: a perfectly regular ring × section tube — the worst case for the exact
  centre search, because whole rings tie in eccentricity.

Prints seconds per step and size, and the growth exponent of the total time
(slope of log(seconds) against log(vertices)).

    .venv/bin/python benchmarks/prepare_garment.py [--sizes 1000 5000 20000 50000]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from data_prep.garments import flared_skirt
from gnngarment.geometry.prepare import GarmentPreparationConfig, prepare_garment


def skirt(num_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """Irregular flared skirt (waist 0.15 m, hem 0.45 m, 0.6 m long)."""
    return flared_skirt(num_vertices, seed=0)


def tube(num_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """Regular tube with 2:1 sections:rings (circumference-dominated, many ties)."""
    rings = max(int(np.sqrt(num_vertices / 2)), 2)
    sections = num_vertices // rings
    angle = 2 * np.pi * np.arange(sections) / sections
    pos = np.concatenate([np.column_stack([0.3 * np.cos(angle), 0.3 * np.sin(angle),
                                           np.full(sections, -0.6 * k / rings)])
                          for k in range(rings)])
    a = (np.arange(rings - 1)[:, None] * sections + np.arange(sections)[None, :]).ravel()
    b = (np.arange(rings - 1)[:, None] * sections
         + (np.arange(sections)[None, :] + 1) % sections).ravel()
    faces = np.concatenate([np.column_stack([a, b, b + sections]),
                            np.column_stack([a, b + sections, a + sections])])
    return pos, faces.astype(np.int64)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1000, 5000, 20000, 50000])
    parser.add_argument("--repeats", type=int, default=3, help="best of this many runs")
    arguments = parser.parse_args()
    config = GarmentPreparationConfig()  # levels 2, 64 landmarks (configs/garment.yaml)

    print(f"{'mesh':6} {'vertices':>9} {'hierarchy s':>12} {'descriptor s':>13} "
          f"{'total s':>9} {'levels (vertices)':>24}")
    for family, build in (("skirt", skirt), ("tube", tube)):
        sizes, totals = [], []
        for size in arguments.sizes:
            pos, faces = build(size)
            best = None
            for _ in range(arguments.repeats):
                start = time.perf_counter()
                prepared = prepare_garment(pos, faces, config)
                total = time.perf_counter() - start
                if best is None or total < best[0]:
                    best = (total, prepared)
            total, prepared = best
            sizes.append(len(pos))
            totals.append(total)
            counts = "/".join(map(str, prepared.hierarchy.vertex_counts()))
            print(f"{family:6} {len(pos):9d} {prepared.seconds['hierarchy']:12.3f} "
                  f"{prepared.seconds['descriptor']:13.3f} {total:9.3f} {counts:>24}")
        slope = np.polyfit(np.log(sizes), np.log(totals), 1)[0]
        print(f"{family:6} growth exponent (log-log slope of total time): {slope:.2f}")


if __name__ == "__main__":
    main()
