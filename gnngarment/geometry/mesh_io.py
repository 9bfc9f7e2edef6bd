"""Read garment meshes without reordering or merging vertices.

Vertex order is the user's contract with their DCC tool (Blender's "Keep Vert Order",
point caches indexed by vertex): everything that comes back from the model is in the
same order, so loading must never weld, sort or drop vertices.
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from gnngarment.geometry.errors import MeshError

#: Extensions trimesh reads for us, mapped to trimesh's file type names.
MESH_FORMATS = {".obj": "obj", ".ply": "ply", ".off": "off", ".stl": "stl", ".glb": "glb",
                ".gltf": "gltf"}


class TexturedMesh(NamedTuple):
    """A mesh file's triangles with its texture coordinates, when it has them.

    Attributes:
        pos: ``(N, 3)`` float64 vertex positions, in the file's order and units.
        faces: ``(F, 3)`` int64 triangles.
        uv: ``(K, 2)`` float64 texture coordinates (OBJ convention: ``v`` up), or
            ``None`` when the file has none (or not for every corner).
        uv_faces: ``(F, 3)`` int64 per-corner indices into ``uv`` (same triangles as
            ``faces``), or ``None`` (see
            :mod:`~gnngarment.geometry.texture_coordinates`).
    """

    pos: np.ndarray
    faces: np.ndarray
    uv: np.ndarray | None
    uv_faces: np.ndarray | None


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Positions and faces of a Wavefront OBJ, exactly as listed in the file.

    trimesh's OBJ loader (even with ``process=False, maintain_order=True``) drops
    vertices that no face references once the file has texture coordinates, which
    shifts every later index; CLOTH3D point caches and DCC round trips index the file's
    ``v`` lines, so OBJ gets this small reader. Polygons are fan-split like trimesh
    does; ``vn``/groups/materials are ignored; negative (relative) indices work.
    :func:`read_textured_obj` also returns the ``vt`` lines.

    Shapes:
        returns ``pos (N, 3)`` float64 and ``faces (F, 3)`` int64.
    """
    mesh = read_textured_obj(path)
    return mesh.pos, mesh.faces


def read_textured_obj(path: Path) -> TexturedMesh:
    """:func:`read_obj` plus the texture coordinates: the ``vt`` table (``u v`` of each
    line, a missing ``v`` read as 0) and each corner's ``vt`` index, fan-split with the
    polygon. UVs are kept only when every face corner names one.

    Raises:
        MeshError: unreadable lines, faces naming missing ``vt`` lines, or no faces.
    """
    positions: list[list[float]] = []
    texcoords: list[list[float]] = []
    triangles: list[list[int]] = []
    uv_triangles: list[list[int]] = []
    every_corner_textured = True
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
                elif words[0] == "vt":
                    if len(words) < 2:
                        raise MeshError(f"{path}:{number}: vt line needs u [v]")
                    texcoords.append([float(words[1]),
                                      float(words[2]) if len(words) > 2 else 0.0])
                elif words[0] == "f":
                    if len(words) < 4:
                        raise MeshError(f"{path}:{number}: face needs at least 3 vertices")
                    corners, uv_corners = [], []
                    for word in words[1:]:
                        fields = word.split("/")
                        corners.append(_obj_index(_integer(fields[0]), len(positions)))
                        if len(fields) > 1 and fields[1]:
                            uv_corners.append(_obj_index(_integer(fields[1]), len(texcoords)))
                    fan = range(1, len(corners) - 1)
                    triangles.extend([corners[0], corners[k], corners[k + 1]] for k in fan)
                    if len(uv_corners) == len(corners):
                        uv_triangles.extend([uv_corners[0], uv_corners[k], uv_corners[k + 1]]
                                            for k in fan)
                    else:
                        every_corner_textured = False
    except MeshError:
        raise
    except (ValueError, UnicodeError) as error:
        raise MeshError(f"{path}: cannot read OBJ file ({error})") from error
    if not triangles:
        raise MeshError(f"{path}: the file holds no faces (a point cloud or empty file)")
    pos = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(triangles, dtype=np.int64)
    if not (every_corner_textured and texcoords):
        return TexturedMesh(pos, faces, None, None)
    uv_faces = np.asarray(uv_triangles, dtype=np.int64)
    if uv_faces.min() < 0 or uv_faces.max() >= len(texcoords):
        raise MeshError(f"{path}: faces name texture coordinates (vt) "
                        f"{uv_faces.min() + 1}..{uv_faces.max() + 1}, the file has "
                        f"{len(texcoords)}")
    return TexturedMesh(pos, faces, np.asarray(texcoords, dtype=np.float64), uv_faces)


def _integer(word: str) -> int:
    """An OBJ index; CLOTH3D's writer prints them as floats (``6893.0``), which only a
    whole number may be."""
    try:
        index = int(word)
    except ValueError:
        value = float(word)
        if not value.is_integer():
            raise ValueError(f"face index {word!r} is not a whole number") from None
        index = int(value)
    # Far beyond any file's vertex count, and beyond int64 (an OverflowError traceback).
    if abs(index) >= 2**62:
        raise ValueError(f"face index {word!r} is out of range")
    return index


def _obj_index(index: int, count: int) -> int:
    """0-based index of an OBJ reference: 1-based, negative counts back from the last
    element read so far."""
    return index - 1 if index > 0 else count + index


def load_mesh(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Load a triangle (or quad) mesh file as arrays, keeping the file's vertex order.

    Quads and polygons are split into triangles by trimesh's fan split; for a quad
    (0, 1, 2, 3) that gives (0, 1, 2), (0, 2, 3). A glTF/GLB scene with several mesh
    primitives is concatenated in scene order (vertex indices offset, nothing merged).
    :func:`load_textured_mesh` also returns the texture coordinates.

    Args:
        path: ``.obj``, ``.ply``, ``.off``, ``.stl``, ``.gltf`` or ``.glb`` file.

    Returns:
        pos: ``(N, 3)`` float64 vertex positions, in the file's units.
        faces: ``(F, 3)`` int64 triangle vertex indices.

    Raises:
        MeshError: missing file, unknown extension, unreadable content, or no faces;
            the message names the file.
    """
    mesh = load_textured_mesh(path)
    return mesh.pos, mesh.faces


def load_textured_mesh(path: str | Path) -> TexturedMesh:
    """:func:`load_mesh` plus the file's texture coordinates, per face corner.

    OBJ: the ``vt`` table and each corner's ``vt`` index as written, so UV seams (one
    vertex, several UVs) survive and the vertices stay the ``v`` lines
    (:func:`read_textured_obj`). Other formats hold one UV per vertex (trimesh's
    ``visual.uv``, already in OBJ convention, ``v`` up): ``uv`` is that ``(N, 2)``
    table and ``uv_faces`` equals ``faces``. A scene keeps UVs only if every mesh has
    them.

    Raises:
        MeshError: as :func:`load_mesh`.
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
        return read_textured_obj(path)
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
    elif isinstance(loaded, trimesh.Trimesh):
        meshes = [loaded]
    else:
        kind = type(loaded).__name__
        raise MeshError(f"{path}: the file holds a {kind}, not a surface mesh (no faces)")
    pos = np.concatenate([np.asarray(m.vertices, dtype=np.float64) for m in meshes])
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    faces = np.concatenate(
        [np.asarray(m.faces, dtype=np.int64).reshape(-1, 3) + o
         for m, o in zip(meshes, offsets, strict=True)])

    if pos.ndim != 2 or pos.shape[1] != 3:
        raise MeshError(f"{path}: vertices have shape {pos.shape}, expected (N, 3)")
    uvs = [_vertex_uv(m) for m in meshes]
    uv = None if any(u is None for u in uvs) else np.concatenate(uvs)
    faces = np.ascontiguousarray(faces)
    return TexturedMesh(np.ascontiguousarray(pos), faces, uv,
                        None if uv is None else faces.copy())


def _vertex_uv(mesh) -> np.ndarray | None:
    """A trimesh mesh's ``(N, 2)`` per-vertex UVs, or ``None``."""
    uv = getattr(mesh.visual, "uv", None)
    if uv is None:
        return None
    uv = np.asarray(uv, dtype=np.float64)
    if uv.shape != (len(mesh.vertices), 2) or not np.isfinite(uv).all():
        return None
    return uv
