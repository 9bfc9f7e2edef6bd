"""Everything computed once per garment topology: validation, edge graph, pooling
hierarchy and style descriptor, with the time each step took."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from gnngarment.geometry.graph import connected_components, edge_index_from_faces
from gnngarment.geometry.hierarchy import PoolHierarchy, pool_hierarchy
from gnngarment.geometry.nystrom import nystrom_descriptor
from gnngarment.geometry.validation import MeshReport, validate_mesh


@dataclass
class GarmentPreparationConfig:
    """Settings of :func:`prepare_garment` (defaults mirror ``configs/garment.yaml``).

    Attributes:
        levels: pooling steps (0 = single level).
        landmarks: N*, landmark count of the Nyström descriptor.
        kernel_width: geodesic affinity width, in units of sqrt(surface area).
    """

    levels: int = 2
    landmarks: int = 64
    kernel_width: float = 0.5


@dataclass
class PreparedGarment:
    """A garment's topology-only data.

    Attributes:
        report: validation findings.
        edge_index: ``(2, E)`` mesh edge graph.
        component: ``(N,)`` component label per vertex.
        hierarchy: pooling hierarchy with unpooling matrices.
        descriptor: ``(landmarks,)`` Nyström style descriptor.
        seconds: wall-clock seconds per step.
    """

    report: MeshReport
    edge_index: np.ndarray
    component: np.ndarray
    hierarchy: PoolHierarchy
    descriptor: np.ndarray
    seconds: dict[str, float] = field(default_factory=dict)


def prepare_garment(pos: np.ndarray, faces: np.ndarray,
                    config: GarmentPreparationConfig | None = None,
                    source: str = "<mesh>") -> PreparedGarment:
    """Validate a garment and compute its hierarchy and descriptor.

    Shapes:
        pos: ``(N, 3)`` rest positions (any unit: everything here is unit-free).
        faces: ``(F, 3)`` triangles.

    Raises:
        MeshError: the mesh is unusable (message names ``source``).
    """
    config = config or GarmentPreparationConfig()
    seconds: dict[str, float] = {}

    start = time.perf_counter()
    report = validate_mesh(pos, faces, source)
    seconds["validate"] = time.perf_counter() - start

    start = time.perf_counter()
    edge_index = edge_index_from_faces(faces, len(pos))
    component = connected_components(edge_index, len(pos))
    seconds["edge_graph"] = time.perf_counter() - start

    start = time.perf_counter()
    hierarchy = pool_hierarchy(edge_index, len(pos), config.levels)
    seconds["hierarchy"] = time.perf_counter() - start

    start = time.perf_counter()
    descriptor = nystrom_descriptor(pos, faces, num_landmarks=config.landmarks,
                                    kernel_width=config.kernel_width)
    seconds["descriptor"] = time.perf_counter() - start

    return PreparedGarment(report=report, edge_index=edge_index, component=component,
                           hierarchy=hierarchy, descriptor=descriptor, seconds=seconds)
