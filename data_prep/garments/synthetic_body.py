"""A cheap human-like body for fast tests: ellipsoids and capsules with SMPL joints.

About Anny's default size (1.63 m, pelvis near the origin, Z up, facing −Y, left = +X),
so garments sized on it look like garments on Anny. It is a union of closed components
(:class:`~data_prep.garments.body_distance.BodyDistance` treats it as such); building it
takes a few milliseconds, against ~1 min for Anny's first construction.
"""

from __future__ import annotations

import numpy as np

from data_prep.garments.body_frame import BodyFrame
from gnngarment.body.skeleton import JOINT_INDEX


def _ellipsoid(center: tuple[float, float, float], radii: tuple[float, float, float],
               subdivisions: int = 3) -> tuple[np.ndarray, np.ndarray]:
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=subdivisions)
    return sphere.vertices * np.asarray(radii) + np.asarray(center), sphere.faces


def _capsule(start: np.ndarray, end: np.ndarray, radius: float,
             spacing: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    """Closed capsule from ``start`` to ``end``: rings of ``sections`` vertices (poles
    as fans), with rings every ``spacing`` metres along the cylinder so no triangle is
    long (the distance query's candidate bound assumes small triangles)."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    axis = end - start
    length = float(np.linalg.norm(axis))
    w = axis / length
    u = np.cross(w, [0.0, 1.0, 0.0] if abs(w[1]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    sections, cap_rings = 24, 6
    # (axial offset, ring radius) from the start pole to the end pole.
    polar = np.linspace(0, np.pi / 2, cap_rings + 1)[1:]
    rings = [(-radius * np.cos(a), radius * np.sin(a)) for a in polar]
    steps = max(int(np.ceil(length / spacing)), 1)
    rings += [(length * k / steps, radius) for k in range(1, steps + 1)]
    rings += [(length + radius * np.sin(a), radius * np.cos(a)) for a in polar[:-1]]
    angles = 2 * np.pi * np.arange(sections) / sections
    circle = np.cos(angles)[:, None] * u + np.sin(angles)[:, None] * v
    vertices = [start - radius * w]
    for offset, ring_radius in rings:
        vertices.extend(start + offset * w + ring_radius * circle)
    vertices.append(end + radius * w)
    vertices = np.array(vertices)
    faces = []
    j = np.arange(sections)
    k = (j + 1) % sections
    faces += list(np.stack([np.zeros(sections, int), 1 + k, 1 + j], axis=1))
    for r in range(len(rings) - 1):
        a, b = 1 + r * sections, 1 + (r + 1) * sections
        faces += list(np.stack([a + j, a + k, b + k], axis=1))
        faces += list(np.stack([a + j, b + k, b + j], axis=1))
    last, top = 1 + (len(rings) - 1) * sections, len(vertices) - 1
    faces += list(np.stack([np.full(sections, top), last + j, last + k], axis=1))
    return vertices, np.array(faces, dtype=np.int64)


def synthetic_body(arm_angle_deg: float = 0.0, scale: float = 1.0, girth: float = 1.0) -> BodyFrame:
    """A human-like body of ellipsoids and capsules, with its 24 SMPL joints.

    Args:
        arm_angle_deg: how far the arms hang below horizontal (0 = T-pose, ~45 = A-pose).
        scale: overall size factor (1 → ~1.63 m tall).
        girth: factor on the torso and limb widths (1 = average build).

    Returns:
        A :class:`BodyFrame` (vertices ``(N_b, 3)``, faces ``(F_b, 3)``, joints ``(24, 3)``).
    """
    g = girth
    angle = np.radians(arm_angle_deg)
    joints = np.zeros((24, 3))

    def put(name: str, xyz: tuple[float, float, float] | np.ndarray) -> None:
        joints[JOINT_INDEX[name]] = xyz

    put("pelvis", (0, 0, 0.05))
    put("spine1", (0, 0.01, 0.15))
    put("spine2", (0, 0.01, 0.27))
    put("spine3", (0, 0.02, 0.39))
    put("neck", (0, 0.0, 0.55))
    put("head", (0, -0.02, 0.65))
    for side, sign in (("L", 1.0), ("R", -1.0)):
        put(f"{side}_hip", (sign * 0.1, 0, 0.0))
        put(f"{side}_knee", (sign * 0.12, -0.01, -0.38))
        put(f"{side}_ankle", (sign * 0.14, 0.02, -0.76))
        put(f"{side}_foot", (sign * 0.14, -0.1, -0.8))
        put(f"{side}_collar", (sign * 0.03, -0.01, 0.49))
        shoulder = np.array([sign * 0.17, 0.0, 0.47])
        direction = np.array([sign * np.cos(angle), 0.0, -np.sin(angle)])
        put(f"{side}_shoulder", shoulder)
        put(f"{side}_elbow", shoulder + 0.26 * direction)
        put(f"{side}_wrist", shoulder + 0.51 * direction)
        put(f"{side}_hand", shoulder + 0.59 * direction)

    parts = [
        _ellipsoid((0, 0.01, 0.02), (0.17 * g, 0.115 * g, 0.13)),
        _ellipsoid((0, 0.01, 0.2), (0.145 * g, 0.1 * g, 0.14)),
        _ellipsoid((0, 0.01, 0.37), (0.16 * g, 0.11 * g, 0.15)),
        _capsule(np.array([-0.15, 0.01, 0.455]), np.array([0.15, 0.01, 0.455]), 0.06 * g),
        _capsule(np.array([0, 0, 0.46]), np.array([0, 0, 0.6]), 0.055 * g),
        _ellipsoid((0, -0.02, 0.7), (0.08, 0.1, 0.115)),
    ]
    for side in ("L", "R"):
        j = {name: joints[JOINT_INDEX[f"{side}_{name}"]] for name in
             ("shoulder", "elbow", "wrist", "hand", "hip", "knee", "ankle", "foot")}
        parts += [
            _capsule(j["shoulder"], j["elbow"], 0.048 * g),
            _capsule(j["elbow"], j["wrist"], 0.038 * g),
            _ellipsoid(tuple(j["hand"]), (0.055, 0.03, 0.055)),
            _capsule(j["hip"], j["knee"], 0.07 * g),
            _capsule(j["knee"], j["ankle"], 0.05 * g),
            _ellipsoid(tuple((j["ankle"] + j["foot"]) / 2 + [0, -0.02, -0.02]),
                       (0.045, 0.11, 0.04)),
        ]
    vertices, faces, offset = [], [], 0
    for v, f in parts:
        vertices.append(v)
        faces.append(np.asarray(f) + offset)
        offset += len(v)
    vertices = np.concatenate(vertices) * scale
    return BodyFrame(vertices=vertices, faces=np.concatenate(faces), joints=joints * scale)
