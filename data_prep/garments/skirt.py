"""Skirts: the body-fitted :class:`SkirtStyle` type, and the stand-alone
:func:`flared_skirt` cone (no body needed; used by the demo and benchmarks)."""

from __future__ import annotations

import dataclasses
from typing import ClassVar

import numpy as np
from scipy.spatial import Delaunay

from data_prep.garments.body_frame import BodyFrame
from data_prep.garments.outline import GarmentOutline
from data_prep.garments.parts import bounds, hem_cut, hem_low, trunk_stack, waist_cut
from data_prep.garments.shapes import Design
from data_prep.garments.style import Style, number


def flared_skirt(num_vertices: int = 2000, waist_radius: float = 0.15,
                 hem_radius: float = 0.45, length: float = 0.6, waist_height: float = 0.0,
                 seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """An open cone (waist ring on top, hem ring below), Z-up, metres.

    The surface is the Delaunay triangulation of random, area-uniform points in a flat
    annulus with evenly spaced rim points, lifted onto the cone, so valences vary as in
    real garments (no eccentricity ties from symmetry) while both openings stay clean
    boundary loops.

    Args:
        num_vertices: approximate vertex count (exact up to the rim rounding).
        waist_radius, hem_radius, length, waist_height: metres.
        seed: random seed of the interior points.

    Returns:
        pos ``(N, 3)`` float64, faces ``(F, 3)`` int64 (outward-facing).
    """
    if num_vertices < 50:
        raise ValueError(f"num_vertices must be >= 50, got {num_vertices}")
    rng = np.random.default_rng(seed)
    inner, outer = 1.0, 3.0
    rim_count = int(np.sqrt(num_vertices) * 2.2)
    angles = 2 * np.pi * np.arange(rim_count) / rim_count
    rims = [np.column_stack([r * np.cos(angles), r * np.sin(angles)]) for r in (inner, outer)]
    interior = num_vertices - 2 * rim_count
    # Area-uniform samples in the annulus, kept off the rims so no sliver hugs them.
    radius = np.sqrt(rng.uniform((inner + 0.02) ** 2, (outer - 0.02) ** 2, interior))
    theta = rng.uniform(0, 2 * np.pi, interior)
    points = np.vstack([*rims, np.column_stack([radius * np.cos(theta),
                                                radius * np.sin(theta)])])
    faces = Delaunay(points).simplices
    faces = faces[np.linalg.norm(points[faces].mean(axis=1), axis=1) > inner]  # the hole
    r = np.linalg.norm(points, axis=1)
    t = (r - inner) / (outer - inner)  # 0 at the waist, 1 at the hem
    scale = (waist_radius + (hem_radius - waist_radius) * t) / r
    pos = np.column_stack([points * scale[:, None], waist_height - length * t])
    used = np.unique(faces)
    remap = np.full(len(pos), -1)
    remap[used] = np.arange(len(used))
    # Delaunay triangles are counter-clockwise seen from +z; lifted onto the downward
    # cone they face outward, away from the body (checked in the tests).
    return pos[used], remap[faces].astype(np.int64)


# ---- body-fitted skirt (the synthetic set's "skirt" type) ---------------------------


@dataclasses.dataclass(frozen=True)
class SkirtStyle(Style):
    """A skirt: a tube from the waist down, widening below the hips."""

    garment_type: ClassVar[str] = "skirt"
    waist_height: float = number(0.5, 0.0, 1.0, "waistband height: 0 = hip joints, 1 = natural "
                                 "waist")
    length: float = number(0.4, 0.15, 0.9, "hem drop as a fraction of waist-to-ankle (mini → "
                           "maxi)")
    flare: float = number(0.3, 0.0, 0.6, "hem widening in metres per metre below the hips "
                          "(0 = straight/pencil)")
    looseness: float = number(0.02, 0.01, 0.045, "ease at the waist and hips (m)")
    front_rise: float = number(0.0, -0.04, 0.1, "how much higher the hem is in front than at the "
                               "back (m; high-low hem)")


def skirt_outline(body: BodyFrame, style: SkirtStyle) -> GarmentOutline:
    """The implicit skirt around ``body``: waist and hem cuts on a skirt stack."""
    m = body.measurements
    z_waist = m.z_hip + style.waist_height * (m.z_waist - m.z_hip)
    z_hem = z_waist - style.length * (z_waist - (m.z_ankle + 0.06))
    z_hem = min(z_hem, m.z_crotch - 0.06)  # a skirt covers the crotch
    stack = trunk_stack(m, z_hem - 0.1, z_waist + 0.1, style.looseness,
                        skirt_from=min(m.z_hip, z_waist - 0.02), flare=style.flare, cap=False,
                        vertices=body.vertices)
    design = Design(solids=[stack],
                    cuts=[waist_cut(z_waist), hem_cut(z_hem, stack, front_rise=style.front_rise)],
                    bounds=bounds([stack], hem_low(z_hem, style.front_rise), z_waist + 0.03))
    return GarmentOutline(design=design, loops=2, top="waist")
