"""Check a garment mesh before anything is computed on it.

Problems that make the mesh unusable (empty, NaN/inf, indices out of range, degenerate
or duplicate faces) are *errors*: :func:`validate_mesh` raises :class:`MeshError`
naming the source and every problem found. Problems the library can live with are
*findings*: unreferenced vertices (they carry no geometry; remove them with
:func:`remove_unreferenced_vertices`, which returns the index map back to the file's
order) and non-manifold edges (more than two faces on one edge: the edge graph,
pooling and normals are still defined). Several connected components are valid — a
garment can be made of several pieces — and are reported, not rejected.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gnngarment.geometry.errors import MeshError
from gnngarment.geometry.normals import face_normals

#: A face is degenerate when its area is below this fraction of the squared bounding-box
#: diagonal. Relative, so the test does not depend on units (metres vs centimetres).
DEGENERATE_AREA_FRACTION = 1e-14


@dataclass
class MeshReport:
    """What :func:`check_mesh` found.

    Attributes:
        source: file name (or a label) used in messages.
        num_vertices, num_faces: counts as given.
        num_components: connected components of the face graph (isolated vertices count).
        errors: problems that make the mesh unusable.
        findings: problems reported but tolerated.
        unreferenced: ``(U,)`` indices of vertices used by no face.
        non_manifold_edges: ``(M, 2)`` vertex pairs shared by more than two faces.
    """

    source: str
    num_vertices: int
    num_faces: int
    num_components: int = 0
    errors: list[str] = field(default_factory=list)
    findings: list[str] = field(default_factory=list)
    unreferenced: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    non_manifold_edges: np.ndarray = field(
        default_factory=lambda: np.zeros((0, 2), dtype=np.int64))

    @property
    def ok(self) -> bool:
        return not self.errors

    def raise_for_errors(self) -> None:
        """Raise :class:`MeshError` listing every error, if there is any."""
        if self.errors:
            raise MeshError(f"{self.source}: invalid mesh: " + "; ".join(self.errors))


def _index_list(indices: np.ndarray, limit: int = 8) -> str:
    shown = ", ".join(str(int(i)) for i in indices[:limit])
    return shown + (", ..." if len(indices) > limit else "")


def check_mesh(pos: np.ndarray, faces: np.ndarray, source: str = "<mesh>") -> MeshReport:
    """Inspect a mesh and report errors and findings without raising.

    Shapes:
        pos: ``(N, 3)`` float vertex positions (any unit).
        faces: ``(F, 3)`` int triangle indices.
    """
    pos = np.asarray(pos)
    faces = np.asarray(faces)
    report = MeshReport(source=source, num_vertices=len(pos) if pos.ndim else 0,
                        num_faces=len(faces) if faces.ndim else 0)
    if pos.ndim != 2 or pos.shape[1] != 3:
        report.errors.append(f"vertices have shape {pos.shape}, expected (N, 3)")
        return report
    if faces.ndim != 2 or faces.shape[1] != 3:
        report.errors.append(f"faces have shape {faces.shape}, expected (F, 3)")
        return report
    if not np.issubdtype(faces.dtype, np.integer):
        report.errors.append(f"faces have dtype {faces.dtype}, expected integers")
        return report
    if len(pos) == 0 or len(faces) == 0:
        report.errors.append(f"empty mesh ({len(pos)} vertices, {len(faces)} faces)")
        return report

    bad_coordinates = np.flatnonzero(~np.isfinite(pos).all(axis=1))
    if len(bad_coordinates):
        report.errors.append(f"{len(bad_coordinates)} vertices have NaN/inf coordinates "
                             f"(vertices {_index_list(bad_coordinates)})")
    out_of_range = np.flatnonzero(((faces < 0) | (faces >= len(pos))).any(axis=1))
    if len(out_of_range):
        report.errors.append(f"{len(out_of_range)} faces index vertices outside 0..{len(pos) - 1} "
                             f"(faces {_index_list(out_of_range)})")
    if report.errors:  # the checks below need valid coordinates and indices
        return report

    repeated = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (
        faces[:, 0] == faces[:, 2])
    double_area = np.linalg.norm(face_normals(pos, faces, normalize=False), axis=1)
    diagonal = float(np.linalg.norm(pos.max(axis=0) - pos.min(axis=0)))
    tiny = double_area <= 2 * DEGENERATE_AREA_FRACTION * max(diagonal, 1e-300) ** 2
    degenerate = np.flatnonzero(repeated | tiny)
    if len(degenerate):
        report.errors.append(f"{len(degenerate)} degenerate (zero-area or repeated-vertex) "
                             f"faces (faces {_index_list(degenerate)})")

    _, first, counts = np.unique(_row_keys(np.sort(faces, axis=1), len(pos)),
                                 return_index=True, return_counts=True)
    if (counts > 1).any():
        duplicated_rows = np.flatnonzero(
            np.isin(np.arange(len(faces)), first, invert=True))
        report.errors.append(f"{len(duplicated_rows)} duplicate faces (same three vertices; "
                             f"faces {_index_list(duplicated_rows)})")

    referenced = np.zeros(len(pos), dtype=bool)
    referenced[faces.ravel()] = True
    report.unreferenced = np.flatnonzero(~referenced)
    if len(report.unreferenced):
        report.findings.append(
            f"{len(report.unreferenced)} unreferenced vertices (vertices "
            f"{_index_list(report.unreferenced)}); remove_unreferenced_vertices() drops them "
            "and returns the index map")

    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]),
                    axis=1)
    edge_keys, edge_counts = np.unique(edges[:, 0] * len(pos) + edges[:, 1],
                                       return_counts=True)
    crowded = edge_keys[edge_counts > 2]
    report.non_manifold_edges = np.stack([crowded // len(pos), crowded % len(pos)], axis=1)
    if len(report.non_manifold_edges):
        report.findings.append(f"{len(report.non_manifold_edges)} non-manifold edges "
                               "(shared by more than two faces)")

    from gnngarment.geometry.graph import connected_components, edge_index_from_faces

    report.num_components = int(
        connected_components(edge_index_from_faces(faces, len(pos)), len(pos)).max() + 1)
    if report.num_components > 1:
        report.findings.append(f"{report.num_components} connected components (valid: each "
                               "is pooled on its own)")
    return report


def _row_keys(rows: np.ndarray, base: int) -> np.ndarray:
    """One integer per ``(R, 3)`` row, equal iff the rows are equal. Integer keys make
    ``np.unique`` ~10x faster than ``axis=0``; fall back to the latter if they overflow."""
    if base ** 3 < 2**62:
        return (rows[:, 0] * base + rows[:, 1]) * base + rows[:, 2]
    return np.unique(rows, axis=0, return_inverse=True)[1].ravel()


def validate_mesh(pos: np.ndarray, faces: np.ndarray, source: str = "<mesh>") -> MeshReport:
    """Like :func:`check_mesh`, but raise :class:`MeshError` if the mesh has errors.

    Returns:
        The report (findings only) for a usable mesh.
    """
    report = check_mesh(pos, faces, source)
    report.raise_for_errors()
    return report


def remove_unreferenced_vertices(
    pos: np.ndarray, faces: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drop vertices that no face uses, keeping the others in their order.

    Returns:
        pos: ``(N', 3)`` kept vertices.
        faces: ``(F, 3)`` faces re-indexed into ``pos``.
        kept: ``(N',)`` index of each kept vertex in the input, so results computed on
            the cleaned mesh map back with ``full[kept] = result``.
    """
    referenced = np.zeros(len(pos), dtype=bool)
    referenced[np.asarray(faces).ravel()] = True
    kept = np.flatnonzero(referenced)
    new_index = np.full(len(pos), -1, dtype=np.int64)
    new_index[kept] = np.arange(len(kept))
    return np.asarray(pos)[kept], new_index[np.asarray(faces)], kept
