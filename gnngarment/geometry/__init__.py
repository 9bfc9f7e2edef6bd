"""Garment mesh geometry: pure numpy/scipy (Warp, imported lazily, for queries against
the body mesh), imports nothing else of gnngarment but the file formats of
:mod:`gnngarment.io` (numpy only).

Public API (arrays in, arrays out; ``pos (N, 3)``, ``faces (F, 3)``, ``edge_index (2, E)``):
"""

from gnngarment.geometry.body_collisions import (
    CollisionSettings,
    CollisionStats,
    resolve_collisions,
)
from gnngarment.geometry.eccentricity import graph_centres, hop_distance
from gnngarment.geometry.errors import MeshError
from gnngarment.geometry.geodesics import farthest_point_sampling, geodesic_distances
from gnngarment.geometry.graph import adjacency_matrix, connected_components, edge_index_from_faces
from gnngarment.geometry.hierarchy import PoolHierarchy, PoolLevel, pool_hierarchy
from gnngarment.geometry.joint_distances import joint_distances
from gnngarment.geometry.mesh_io import TexturedMesh, load_mesh, load_textured_mesh
from gnngarment.geometry.normals import face_normals, vertex_normals
from gnngarment.geometry.nystrom import nystrom_descriptor
from gnngarment.geometry.pooling import PooledGraph, pool
from gnngarment.geometry.prepare import GarmentPreparationConfig, PreparedGarment, prepare_garment
from gnngarment.geometry.scale import mesh_scale, surface_area, vertex_areas
from gnngarment.geometry.unpooling import unpooling_matrix
from gnngarment.geometry.validation import (
    MeshReport,
    check_mesh,
    remove_unreferenced_vertices,
    validate_mesh,
)

__all__ = [
    "CollisionSettings", "CollisionStats", "GarmentPreparationConfig", "MeshError",
    "MeshReport", "PoolHierarchy", "PoolLevel", "PooledGraph", "PreparedGarment", "TexturedMesh",
    "adjacency_matrix", "check_mesh", "connected_components", "edge_index_from_faces",
    "face_normals", "farthest_point_sampling", "geodesic_distances", "graph_centres",
    "hop_distance", "joint_distances", "load_mesh", "load_textured_mesh", "mesh_scale",
    "nystrom_descriptor", "pool", "pool_hierarchy", "prepare_garment",
    "remove_unreferenced_vertices", "resolve_collisions", "surface_area", "unpooling_matrix",
    "validate_mesh", "vertex_areas", "vertex_normals",
]
