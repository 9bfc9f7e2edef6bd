"""Evaluate a glTF 2.0 binary in numpy, the way a viewer does: node TRS animation, morph
target weights, then skinning. Used to measure what an exported ``.glb`` really shows.

Scope: what :func:`~gnngarment.inference.export.gltf.write_glb` writes and the common
cases around it (embedded buffer, STEP/LINEAR samplers, any number of morph targets and
``JOINTS_n``/``WEIGHTS_n`` sets); sparse accessors and CUBICSPLINE are rejected clearly.
The container and its JSON are parsed here with ``struct``/``json`` (not with the
``pygltflib`` the writer uses), so a round trip checks the file, not one library twice.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gnngarment.inference.export.skeleton_animation import quaternion_to_matrix

#: glTF componentType → numpy dtype.
COMPONENT_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
                    5125: np.uint32, 5126: np.float32}
#: glTF accessor type → components per element.
TYPE_SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


@dataclass(frozen=True)
class GlbFile:
    """A parsed ``.glb``: the JSON document (plain dicts and lists, glTF key names) and
    its binary chunk."""

    document: dict[str, Any]
    blob: bytes

    def accessor(self, index: int) -> np.ndarray:
        """Accessor ``index`` as an ``(count, components)`` array (matrices flattened
        column-major, as stored), in its component dtype."""
        accessor = self.document["accessors"][index]
        if "sparse" in accessor:
            raise ValueError(f"accessor {index}: sparse accessors are not supported")
        dtype = np.dtype(COMPONENT_DTYPES[accessor["componentType"]]).newbyteorder("<")
        width = TYPE_SIZES[accessor["type"]]
        count = accessor["count"]
        if "bufferView" not in accessor:
            return np.zeros((count, width), dtype=dtype)
        view = self.document["bufferViews"][accessor["bufferView"]]
        if view["buffer"] != 0:
            raise ValueError(f"accessor {index}: only the GLB's own buffer 0 is supported")
        start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
        element = dtype.itemsize * width
        stride = view.get("byteStride", element)
        size = stride * (count - 1) + element if count else 0
        raw = np.frombuffer(self.blob, dtype=np.uint8, count=size, offset=start)
        if stride == element:
            return raw.view(dtype).reshape(count, width)
        rows = np.lib.stride_tricks.as_strided(raw, (count, element), (stride, 1))
        return np.ascontiguousarray(rows).view(dtype).reshape(count, width)

    def node_index(self, name: str) -> int:
        """Index of the node called ``name``."""
        for index, node in enumerate(self.document["nodes"]):
            if node.get("name") == name:
                return index
        raise KeyError(f"no node named {name!r}")


def read_glb(path: str | Path) -> GlbFile:
    """Parse a ``.glb`` file.

    Raises:
        ValueError: not a readable binary glTF 2.0 file; the message names it.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise ValueError(f"{path}: cannot read ({error})") from error
    if len(data) < 20 or data[:4] != b"glTF":
        raise ValueError(f"{path}: not a binary glTF file (no 'glTF' magic)")
    version, length = struct.unpack_from("<II", data, 4)
    if version != 2 or length != len(data):
        raise ValueError(f"{path}: glTF version {version}, declared length {length} for "
                         f"{len(data)} bytes")
    chunks, offset = {}, 12
    while offset + 8 <= len(data):
        size, kind = struct.unpack_from("<II", data, offset)
        chunks.setdefault(kind, data[offset + 8:offset + 8 + size])
        offset += 8 + size
    if 0x4E4F534A not in chunks:  # "JSON"
        raise ValueError(f"{path}: no JSON chunk")
    try:
        document = json.loads(chunks[0x4E4F534A].decode("utf-8"))
    except (UnicodeError, ValueError) as error:
        raise ValueError(f"{path}: corrupt JSON chunk ({error})") from error
    return GlbFile(document=document, blob=chunks.get(0x004E4942, b""))  # "BIN\0"


def keyframe_times(glb: GlbFile, animation: int = 0) -> np.ndarray:
    """Sorted union of the input times (seconds) of one animation's samplers."""
    samplers = glb.document["animations"][animation]["samplers"]
    return np.unique(np.concatenate([glb.accessor(s["input"])[:, 0] for s in samplers]))


def evaluate_mesh_node(glb: GlbFile, node: int | str, times: np.ndarray | None = None,
                       animation: int = 0) -> np.ndarray:
    """World positions of a mesh node's vertices at the given times.

    Morph targets are applied first (``base + Σ_k w_k target_k``), then the skin (the
    node's own transform is ignored for skinned meshes, as the spec says) or, unskinned,
    the node's global transform.

    Args:
        glb: the parsed file.
        node: node index or name; its mesh must have one primitive.
        times: ``(K,)`` seconds; default every keyframe time of the animation.
        animation: which animation plays (none if the file has none).

    Returns:
        ``(K, N, 3)`` float64 positions in the file's frame (glTF: Y up, metres).
    """
    document = glb.document
    index = glb.node_index(node) if isinstance(node, str) else node
    mesh_node = document["nodes"][index]
    if "mesh" not in mesh_node:
        raise ValueError(f"node {index} has no mesh")
    mesh = document["meshes"][mesh_node["mesh"]]
    if len(mesh["primitives"]) != 1:
        raise ValueError(f"node {index}: meshes with {len(mesh['primitives'])} primitives "
                         f"are not supported")
    primitive = mesh["primitives"][0]
    base = glb.accessor(primitive["attributes"]["POSITION"]).astype(np.float64)
    targets = [glb.accessor(target["POSITION"]).astype(np.float64)
               for target in primitive.get("targets", [])]
    has_animation = bool(document.get("animations"))
    if times is None:
        times = keyframe_times(glb, animation) if has_animation else np.zeros(1)
    times = np.atleast_1d(np.asarray(times, dtype=np.float64))
    channels = _channels(glb, animation) if has_animation else {}
    parents = {child: parent for parent, n in enumerate(document["nodes"])
               for child in n.get("children", [])}
    skin = document["skins"][mesh_node["skin"]] if "skin" in mesh_node else None
    if skin is not None:
        inverse_bind = (glb.accessor(skin["inverseBindMatrices"]).astype(np.float64)
                        .reshape(-1, 4, 4).transpose(0, 2, 1)  # stored column-major
                        if "inverseBindMatrices" in skin
                        else np.tile(np.eye(4), (len(skin["joints"]), 1, 1)))
        joints, weights = _influences(glb, primitive["attributes"])
    static_weights = np.asarray(mesh_node.get("weights", mesh.get("weights",
                                                                  [0.0] * len(targets))),
                                dtype=np.float64)
    out = np.empty((len(times), len(base), 3))
    for k, t in enumerate(times):
        morph = channels.get((index, "weights"))
        morph_weights = _sample(morph, t) if morph is not None else static_weights
        points = base.copy()
        for weight, target in zip(morph_weights, targets, strict=True):
            if weight != 0.0:
                points += weight * target
        cache: dict[int, np.ndarray] = {}
        if skin is not None:
            matrices = np.stack([_global(glb, j, t, channels, parents, cache)
                                 for j in skin["joints"]]) @ inverse_bind
            blended = np.einsum("nk,nkab->nab", weights, matrices[joints][..., :3, :])
            out[k] = np.einsum("nab,nb->na", blended[..., :3], points) + blended[..., 3]
        else:
            matrix = _global(glb, index, t, channels, parents, cache)
            out[k] = points @ matrix[:3, :3].T + matrix[:3, 3]
    return out


def _influences(glb: GlbFile, attributes: dict[str, int]) -> tuple[np.ndarray, np.ndarray]:
    """``(N, 4·sets)`` joint indices and float64 weights of a skinned primitive."""
    joints, weights, n = [], [], 0
    while f"JOINTS_{n}" in attributes:
        joints.append(glb.accessor(attributes[f"JOINTS_{n}"]).astype(np.int64))
        raw = glb.accessor(attributes[f"WEIGHTS_{n}"])
        if raw.dtype == np.uint8:  # normalized integer weights
            raw = raw / 255.0
        elif raw.dtype == np.uint16:
            raw = raw / 65535.0
        weights.append(raw.astype(np.float64))
        n += 1
    if not joints:
        raise ValueError("skinned primitive has no JOINTS_0/WEIGHTS_0")
    return np.concatenate(joints, axis=1), np.concatenate(weights, axis=1)


def _channels(glb: GlbFile, animation: int) -> dict[tuple[int, str], tuple]:
    """``(node, path) → (times, values (K, width), interpolation)`` of one animation."""
    anim = glb.document["animations"][animation]
    out = {}
    for channel in anim["channels"]:
        sampler = anim["samplers"][channel["sampler"]]
        interpolation = sampler.get("interpolation", "LINEAR")
        if interpolation == "CUBICSPLINE":
            raise ValueError("CUBICSPLINE samplers are not supported")
        times = glb.accessor(sampler["input"])[:, 0].astype(np.float64)
        values = glb.accessor(sampler["output"]).astype(np.float64).reshape(len(times), -1)
        target = channel["target"]
        if "node" in target:
            out[(target["node"], target["path"])] = (times, values, interpolation,
                                                     target["path"])
    return out


def _sample(channel: tuple, t: float) -> np.ndarray:
    """A sampler's value at time ``t`` (clamped to its range)."""
    times, values, interpolation, path = channel
    if t <= times[0]:
        return values[0]
    if t >= times[-1]:
        return values[-1]
    upper = int(np.searchsorted(times, t, side="right"))
    lower = upper - 1
    if interpolation == "STEP" or times[lower] == t:
        return values[lower]
    factor = (t - times[lower]) / (times[upper] - times[lower])
    a, b = values[lower], values[upper]
    if path == "rotation":
        return _slerp(a, b, factor)
    return (1 - factor) * a + factor * b


def _slerp(a: np.ndarray, b: np.ndarray, factor: float) -> np.ndarray:
    dot = float(np.dot(a, b))
    if dot < 0:  # shortest path, as the spec's reference implementation
        b, dot = -b, -dot
    if dot > 0.9995:
        q = (1 - factor) * a + factor * b
        return q / np.linalg.norm(q)
    angle = np.arccos(dot)
    return (np.sin((1 - factor) * angle) * a + np.sin(factor * angle) * b) / np.sin(angle)


def _local(glb: GlbFile, index: int, t: float, channels: dict) -> np.ndarray:
    """Node ``index``'s local 4×4 at time ``t`` (matrix, or animated/static TRS)."""
    node = glb.document["nodes"][index]
    if "matrix" in node:
        return np.asarray(node["matrix"], dtype=np.float64).reshape(4, 4).T
    translation = np.asarray(node.get("translation", [0.0, 0.0, 0.0]), dtype=np.float64)
    rotation = np.asarray(node.get("rotation", [0.0, 0.0, 0.0, 1.0]), dtype=np.float64)
    scale = np.asarray(node.get("scale", [1.0, 1.0, 1.0]), dtype=np.float64)
    if (index, "translation") in channels:
        translation = _sample(channels[(index, "translation")], t)
    if (index, "rotation") in channels:
        rotation = _sample(channels[(index, "rotation")], t)
    if (index, "scale") in channels:
        scale = _sample(channels[(index, "scale")], t)
    matrix = np.eye(4)
    matrix[:3, :3] = quaternion_to_matrix(rotation) * scale[None, :]
    matrix[:3, 3] = translation
    return matrix


def _global(glb: GlbFile, index: int, t: float, channels: dict, parents: dict[int, int],
            cache: dict[int, np.ndarray]) -> np.ndarray:
    if index not in cache:
        local = _local(glb, index, t, channels)
        parent = parents.get(index)
        cache[index] = local if parent is None else (
            _global(glb, parent, t, channels, parents, cache) @ local)
    return cache[index]
