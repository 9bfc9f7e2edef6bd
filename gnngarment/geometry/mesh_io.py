"""Read garment meshes without reordering or merging vertices.

Vertex order is the user's contract with their DCC tool (Blender's "Keep Vert Order",
point caches indexed by vertex): everything that comes back from the model is in the
same order, so loading must never weld, sort or drop vertices.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gnngarment.geometry.errors import MeshError

#: Extensions trimesh reads for us, mapped to trimesh's file type names.
MESH_FORMATS = {".obj": "obj", ".ply": "ply", ".off": "off", ".stl": "stl", ".glb": "glb",
                ".gltf": "gltf"}


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Positions and faces of a Wavefront OBJ, exactly as listed in the file.

    trimesh's OBJ loader (even with ``process=False, maintain_order=True``) drops
    vertices that no face references once the file has texture coordinates, which
    shifts every later index; CLOTH3D point caches and DCC round trips index the file's
    ``v`` lines, so OBJ gets this small reader. Polygons are fan-split like trimesh
    does; ``vt``/``vn``/groups/materials are ignored; negative (relative) indices work.

    Shapes:
        returns ``pos (N, 3)`` float64 and ``faces (F, 3)`` int64.
    """
    positions: list[list[float]] = []
    triangles: list[list[int]] = []
    try:
        with open(path, encoding="utf-8", errors="replace") as stream:
            for number, line in enumerate(stream, start=1):
                words = line.split()
                if not words:
                    continue
                if words[0] == "v":
                    if len(words) < 4:
                        raise MeshError(
                            f"{path}:{number}: vertex line needs x y z: {line.strip()!r}")
                    positions.append([float(w) for w in words[1:4]])
                elif words[0] == "f":
                    if len(words) < 4:
                        raise MeshError(f"{path}:{number}: face needs at least 3 vertices")
                    corners = []
                    for word in words[1:]:
                        index = int(word.split("/")[0])
                        # OBJ is 1-based; negative indices count back from the last vertex.
                        corners.append(index - 1 if index > 0 else len(positions) + index)
                    triangles.extend([corners[0], corners[k], corners[k + 1]]
                                     for k in range(1, len(corners) - 1))
    except MeshError:
        raise
    except (ValueError, UnicodeError) as error:
        raise MeshError(f"{path}: cannot read OBJ file ({error})") from error
    if not triangles:
        raise MeshError(f"{path}: the file holds no faces (a point cloud or empty file)")
    pos = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    return pos, np.asarray(triangles, dtype=np.int64)


def load_mesh(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Load a triangle (or quad) mesh file as arrays, keeping the file's vertex order.

    Quads and polygons are split into triangles by trimesh's fan split; for a quad
    (0, 1, 2, 3) that gives (0, 1, 2), (0, 2, 3). A glTF/GLB scene with several mesh
    primitives is concatenated in scene order (vertex indices offset, nothing merged).

    Args:
        path: ``.obj``, ``.ply``, ``.off``, ``.stl``, ``.gltf`` or ``.glb`` file.

    Returns:
        pos: ``(N, 3)`` float64 vertex positions, in the file's units.
        faces: ``(F, 3)`` int64 triangle vertex indices.

    Raises:
        MeshError: missing file, unknown extension, unreadable content, or no faces;
            the message names the file.
    """
    import trimesh

    path = Path(path)
    if not path.is_file():
        raise MeshError(f"{path}: file not found")
    file_type = MESH_FORMATS.get(path.suffix.lower())
    if file_type is None:
        known = ", ".join(sorted(MESH_FORMATS))
        raise MeshError(f"{path}: unknown mesh format '{path.suffix}' (expected one of {known})")
    if file_type == "obj":
        return read_obj(path)
    try:
        loaded = trimesh.load(path, file_type=file_type, process=False, maintain_order=True,
                              force=None)
    except Exception as error:  # trimesh raises many kinds for broken files
        raise MeshError(f"{path}: cannot read {file_type.upper()} file ({error})") from error

    if isinstance(loaded, trimesh.Scene):
        # dump() applies each node's transform; concatenating keeps per-primitive order.
        meshes = [g for g in loaded.dump() if isinstance(g, trimesh.Trimesh)]
        if not meshes:
            raise MeshError(f"{path}: the file holds no triangle mesh")
        pos = np.concatenate([np.asarray(m.vertices, dtype=np.float64) for m in meshes])
        offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
        faces = np.concatenate(
            [np.asarray(m.faces, dtype=np.int64) + o for m, o in zip(meshes, offsets, strict=True)]
        )
    elif isinstance(loaded, trimesh.Trimesh):
        pos = np.asarray(loaded.vertices, dtype=np.float64)
        faces = np.asarray(loaded.faces, dtype=np.int64)
    else:
        kind = type(loaded).__name__
        raise MeshError(f"{path}: the file holds a {kind}, not a surface mesh (no faces)")

    if pos.ndim != 2 or pos.shape[1] != 3:
        raise MeshError(f"{path}: vertices have shape {pos.shape}, expected (N, 3)")
    faces = faces.reshape(-1, 3) if faces.size else np.zeros((0, 3), dtype=np.int64)
    return np.ascontiguousarray(pos), np.ascontiguousarray(faces)
