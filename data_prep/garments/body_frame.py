"""The body a garment is built around, as plain arrays (no body-model import)."""

from __future__ import annotations

import dataclasses
import functools
from typing import TYPE_CHECKING

import numpy as np

from gnngarment.body.skeleton import JOINT_INDEX, JOINT_NAMES
from gnngarment.geometry.graph import largest_component as graph_largest_component

if TYPE_CHECKING:
    from data_prep.garments.body_distance import BodyDistance
    from data_prep.garments.measurements import BodyMeasurements

@dataclasses.dataclass(eq=False)
class BodyFrame:
    """A rest body: closed triangle mesh + the 24 joints, Z up, metres, facing −Y.

    Any body model fits (Anny in T- or A-pose, SMPL, the synthetic test body): the
    garment generator only needs the surface and the joints. The mesh must be closed
    (watertight, outward winding); several closed components are allowed and are read
    as their union (the signed distance is the minimum over components).

    Shapes:
        vertices: ``(N_b, 3)`` float, metres.
        faces: ``(F_b, 3)`` int.
        joints: ``(24, 3)`` float, SMPL order (:data:`JOINT_NAMES`); ``L_*`` is the
            body's left, +X.

    Measurements and the distance structure are computed on first use and cached on the
    instance, so build many garments around one ``BodyFrame``.
    """

    vertices: np.ndarray
    faces: np.ndarray
    joints: np.ndarray

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(self.vertices, dtype=np.float64)
        self.faces = np.ascontiguousarray(self.faces, dtype=np.int64)
        self.joints = np.ascontiguousarray(self.joints, dtype=np.float64)
        if self.vertices.ndim != 2 or self.vertices.shape[1] != 3 or len(self.vertices) < 4:
            raise ValueError(f"body vertices have shape {self.vertices.shape}, expected (N_b, 3)")
        if self.faces.ndim != 2 or self.faces.shape[1] != 3 or len(self.faces) < 4:
            raise ValueError(f"body faces have shape {self.faces.shape}, expected (F_b, 3)")
        if self.faces.min() < 0 or self.faces.max() >= len(self.vertices):
            raise ValueError("body faces index vertices out of range")
        if self.joints.shape != (len(JOINT_NAMES), 3):
            raise ValueError(f"joints have shape {self.joints.shape}, expected (24, 3)")
        if not (np.isfinite(self.vertices).all() and np.isfinite(self.joints).all()):
            raise ValueError("body vertices or joints contain NaN/inf")

    def joint(self, name: str) -> np.ndarray:
        """``(3,)`` position of a joint by SMPL name (e.g. ``"L_shoulder"``)."""
        return self.joints[JOINT_INDEX[name]]

    @functools.cached_property
    def distance(self) -> BodyDistance:
        """Exact signed distance to the body surface (built once, cached)."""
        from data_prep.garments.body_distance import BodyDistance

        return BodyDistance(self.vertices, self.faces)

    @functools.cached_property
    def measurements(self) -> BodyMeasurements:
        """Cross-section and limb profiles the garments are sized from (cached)."""
        from data_prep.garments.measurements import measure_body

        return measure_body(self)


def largest_component(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Keep the largest connected component (Anny's body without tongue and eyes):
    vertices ``(N', 3)`` and faces ``(F', 3)`` re-indexed into them
    (:func:`gnngarment.geometry.graph.largest_component`)."""
    keep, kept_faces = graph_largest_component(faces, len(vertices))
    return np.asarray(vertices)[keep], kept_faces
