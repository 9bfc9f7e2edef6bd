"""glTF 2.0 binary (``.glb``) export: the garment as a skinned mesh on the 24-joint
skeleton, plus per-frame morph targets, so engines play back the predicted animation.

What is written (see ``docs/export.md``):

* **Skeleton**: 24 joint nodes (``JOINT_NAMES``), hierarchy ``JOINT_PARENTS``, rest
  translations from the rest joints, inverse bind matrices ``T(−J_j)``; per-joint
  translation + rotation tracks (LINEAR) recomposing ``Animation.joint_transforms``
  (:mod:`~gnngarment.inference.export.skeleton_animation`).
* **Skin**: the model's weights change every frame and are dense over 24 joints; glTF
  holds one set of 4 (``JOINTS_0``/``WEIGHTS_0``) or 8 influences. The static skin is the
  top-K of the time-averaged weights, renormalised
  (:mod:`~gnngarment.inference.export.static_skin`).
* **Morph targets**: one per frame, the rest-frame residual that makes "static skin +
  target" reproduce ``Animation.posed`` at that frame; a weights track switches target
  ``t`` on at frame ``t`` (LINEAR by default: between frames the residual cross-fades).
* **Axes**: glTF is Y up with the asset facing +Z; the library's world is Z up facing −Y,
  so every position and transform is rotated by :data:`GLTF_FROM_WORLD` (−90° about X).
  Importers (Blender's included) rotate back to Z up.
* **UVs** (``Animation.uv``): ``TEXCOORD_0`` with ``v`` flipped (glTF's origin is the
  image's top-left). glTF has one UV per vertex, so vertices on a UV seam are duplicated
  in the glb (:func:`~gnngarment.geometry.texture_coordinates.split_uv_seams`): vertex
  ``i < N`` is input vertex ``i``, the duplicates follow and ``mesh.extras.seamSources``
  names the input vertex of each.
* **Time**: frame ``k`` is keyed at ``(first_frame + k) / fps`` s; Blender's importer
  puts time ``t`` at scene frame ``t · fps``, so the glb's frames carry the numbers of
  the OBJ files and the ``.pc2`` header.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from numbers import Integral
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gnngarment.body.skeleton import JOINT_NAMES
from gnngarment.geometry.normals import vertex_normals
from gnngarment.geometry.texture_coordinates import SeamSplit, split_uv_seams
from gnngarment.inference.export.gltf_reader import evaluate_mesh_node, read_glb
from gnngarment.inference.export.skeleton_animation import (
    SkeletonAnimation,
    skeleton_animation,
)
from gnngarment.inference.export.static_skin import (
    StaticSkin,
    rest_frame_residuals,
    skin_static,
    static_skin,
)
from gnngarment.inference.export.validation import check_animation
from gnngarment.io.atomic import atomic_write_bytes

if TYPE_CHECKING:
    from gnngarment.inference.animate import Animation

#: Rotation taking the library's world (Z up, front −Y) to glTF's (Y up, front +Z):
#: ``(x, y, z) ↦ (x, z, −y)``.
GLTF_FROM_WORLD = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])

FLOAT, UNSIGNED_BYTE, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5121, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
INTERPOLATIONS = ("LINEAR", "STEP")
GARMENT_COLOUR = (0.80, 0.30, 0.22, 1.0)
BODY_COLOUR = (0.70, 0.70, 0.70, 1.0)


@dataclass(frozen=True)
class GlbExport:
    """What :func:`write_glb` wrote, and how faithfully.

    Errors compare the ``.glb`` as a viewer evaluates it (decoded back from the written
    bytes by :mod:`~gnngarment.inference.export.gltf_reader`) with ``Animation.posed`` at
    every frame time, in metres.

    Attributes:
        path: the file.
        num_frames: frames (= morph targets = keyframes).
        max_influences: joints per vertex in the static skin.
        max_error: largest vertex distance, glb vs prediction (float32 rounding only).
        mean_error: mean vertex distance.
        skin_only_max_error, skin_only_mean_error: the same without the morph targets
            (static skin alone): how much the per-frame residuals carry.
        max_residual: largest morph target displacement (rest frame).
        ill_conditioned: (frame, vertex) pairs solved in the least-squares sense.
        num_bytes: file size.
        seam_vertices: vertices duplicated along UV seams (0 without UVs); the glb
            garment has ``N + seam_vertices`` vertices.
        start_time: seconds of the first keyframe, ``first_frame / fps``.
    """

    path: Path
    num_frames: int
    max_influences: int
    max_error: float | None
    mean_error: float | None
    skin_only_max_error: float
    skin_only_mean_error: float
    max_residual: float
    ill_conditioned: int
    num_bytes: int
    seam_vertices: int = 0
    start_time: float = 0.0


def write_glb(animation: Animation, path: str | Path, *, name: str = "garment",
              max_influences: int = 4, reference: str | int = "mean",
              morph_interpolation: str = "LINEAR", include_body: bool = False,
              normals: bool = True, verify: bool = True, first_frame: int = 0) -> GlbExport:
    """Write the animated garment as a skinned, morph-animated glTF binary, atomically.

    Args:
        animation: the prediction (``posed (T, N, 3)``, ``weights (T, N, 24)``,
            ``joint_transforms (T, 24, 4, 4)``, ``rest_joints (24, 3)``, ``fps``).
        path: destination ``.glb``; its folder must exist.
        name: mesh/node/animation name.
        max_influences: 1..8 joints per vertex (4 fits every engine; 8 adds
            ``JOINTS_1``/``WEIGHTS_1``). The residual targets absorb the truncation.
        reference: weights the static skin takes its top-K from: ``"mean"`` over time or
            a frame index.
        morph_interpolation: ``"LINEAR"`` (targets cross-fade between frames, smooth at
            any playback rate) or ``"STEP"`` (target ``t`` held until frame ``t + 1``).
            Both reproduce the prediction exactly at frame times.
        include_body: also write the posed body as a morph-only mesh (no skin; target
            ``t`` is frame ``t`` minus frame 0). About ``12 · T · N_b`` bytes.
        normals: write garment normals and per-frame normal deltas (smooth shading
            that follows the cloth); without them viewers shade flat.
        verify: decode the written file and measure its error (``GlbExport.max_error``).
        first_frame: frame number of ``posed[0]``: frame ``k`` is keyed at
            ``(first_frame + k) / fps`` seconds, which Blender's importer places at scene
            frame ``first_frame + k`` (0: the animation starts at time 0, as engines
            expect).

    With ``Animation.uv`` the garment carries ``TEXCOORD_0``, its seam vertices split
    (positions, skin, morph targets and normals copied to each duplicate).

    Returns:
        The export summary.

    Raises:
        ValueError: inconsistent animation arrays or bad options.
    """
    return write_outfit_glb([(name, animation)], path, name=name,
                            max_influences=max_influences, reference=reference,
                            morph_interpolation=morph_interpolation,
                            include_body=include_body, normals=normals, verify=verify,
                            first_frame=first_frame)


#: Garment colours of an outfit's glb, innermost first (the first is a single garment's).
GARMENT_COLOURS = (GARMENT_COLOUR, (0.22, 0.38, 0.75, 1.0), (0.25, 0.60, 0.32, 1.0),
                   (0.85, 0.70, 0.20, 1.0))


def write_outfit_glb(parts: Sequence[tuple[str, Animation]], path: str | Path, *,
                     name: str = "outfit", max_influences: int = 4,
                     reference: str | int = "mean", morph_interpolation: str = "LINEAR",
                     include_body: bool = False, normals: bool = True, verify: bool = True,
                     first_frame: int = 0) -> GlbExport:
    """Write several garments animated on one body as one glb: one skinned, morph-animated
    mesh per garment (named ``parts[k][0]``) on one skeleton, one animation.

    Every part must share the skeleton's motion (``joint_transforms``, ``rest_joints``,
    ``fps``, frame count); the body comes from the first. Options as :func:`write_glb`;
    the errors in the returned :class:`GlbExport` are over all garments (largest, mean),
    ``seam_vertices`` and ``ill_conditioned`` summed.

    Raises:
        ValueError: no part, parts that do not share the motion, or bad options.
    """
    import pygltflib

    if not parts:
        raise ValueError("write_outfit_glb needs at least one garment")
    for _, animation in parts:
        check_animation(animation)
    first = parts[0][1]
    for part_name, animation in parts[1:]:
        if (len(animation.posed) != len(first.posed) or animation.fps != first.fps
                or not np.array_equal(animation.joint_transforms, first.joint_transforms)
                or not np.array_equal(animation.rest_joints, first.rest_joints)):
            raise ValueError(f"{part_name}: its motion differs from {parts[0][0]}'s (an "
                             "outfit's garments share one skeleton and its frames)")
    if len({part_name for part_name, _ in parts}) != len(parts):
        raise ValueError("the garments of an outfit glb need different names")
    if morph_interpolation not in INTERPOLATIONS:
        raise ValueError(f"morph_interpolation must be one of {INTERPOLATIONS}, "
                         f"got {morph_interpolation!r}")
    if not 1 <= max_influences <= 8:
        raise ValueError(f"max_influences must be in 1..8, got {max_influences}")
    if not isinstance(first_frame, Integral) or first_frame < 0:
        raise ValueError(f"first_frame must be an integer ≥ 0 (glTF times are ≥ 0), "
                         f"got {first_frame!r}")
    path = Path(path)
    frames = len(first.posed)
    convert = GLTF_FROM_WORLD
    convert4 = np.eye(4)
    convert4[:3, :3] = convert
    transforms = convert4 @ np.asarray(first.joint_transforms, dtype=np.float64) @ convert4.T
    rest_joints = np.asarray(first.rest_joints, dtype=np.float64) @ convert.T

    # Tracks as the file stores them (float32), and the transforms a viewer rebuilds.
    tracks = _float32_tracks(skeleton_animation(transforms, rest_joints))
    viewer_transforms = tracks.skinning_transforms()
    builder = _Builder()
    nodes, joint_nodes = _skeleton_nodes(tracks)
    targets = [f"frame_{t:04d}" for t in range(frames)]
    meshes, materials, scene_nodes = [], [], [0]
    garment_nodes: list[tuple[int, np.ndarray]] = []   # node, expected (T, N', 3)
    skin_only, residual_max, ill_conditioned, seams = [], 0.0, 0, 0
    for k, (part_name, animation) in enumerate(parts):
        rest = np.asarray(animation.rest_pos, dtype=np.float64) @ convert.T
        posed = np.asarray(animation.posed, dtype=np.float64) @ convert.T
        skin = static_skin(animation.weights, max_influences, reference)
        rest32 = rest.astype(np.float32).astype(np.float64)
        residuals = rest_frame_residuals(rest32, posed, skin, viewer_transforms)
        skin_only.append(np.linalg.norm(
            skin_static(rest32, None, skin, viewer_transforms) - posed, axis=-1).ravel())
        residual_max = max(residual_max,
                           float(np.linalg.norm(residuals.offsets, axis=-1).max()))
        ill_conditioned += residuals.ill_conditioned
        faces = np.asarray(animation.faces, dtype=np.int64)
        split = None
        if animation.uv is not None:
            split = split_uv_seams(faces, animation.uv, animation.uv_faces, len(rest32))
            seams += split.seam_vertices
        primitive = _garment_primitive(builder, rest32, faces, residuals.offsets, skin,
                                       normals, split, material=len(materials))
        extras: dict = {"targetNames": targets}
        if split is not None and split.seam_vertices:
            extras["seamSources"] = split.source[len(rest32):].tolist()
        nodes.append(pygltflib.Node(name=part_name, mesh=len(meshes), skin=0))
        meshes.append(pygltflib.Mesh(name=part_name, primitives=[primitive],
                                     weights=_one_hot(frames, 0).tolist(), extras=extras))
        materials.append(_material(f"{part_name}_material",
                                   GARMENT_COLOURS[k % len(GARMENT_COLOURS)],
                                   double_sided=True))
        garment_nodes.append((len(nodes) - 1, posed if split is None else posed[:, split.source]))
        scene_nodes.append(len(nodes) - 1)
    morph_nodes = [(node, morph_interpolation) for node, _ in garment_nodes]
    if include_body:
        body = np.asarray(first.body_vertices, dtype=np.float64) @ convert.T
        body_primitive = _morph_only_primitive(builder, body,
                                               np.asarray(first.body_faces, np.int64),
                                               material=len(materials))
        nodes.append(pygltflib.Node(name="body", mesh=len(meshes)))
        meshes.append(pygltflib.Mesh(name="body", primitives=[body_primitive],
                                     weights=_one_hot(frames, 0).tolist(),
                                     extras={"targetNames": targets}))
        materials.append(_material("body_material", BODY_COLOUR, double_sided=False))
        scene_nodes.append(len(nodes) - 1)
        morph_nodes.append((len(nodes) - 1, morph_interpolation))

    times = (first_frame + np.arange(frames, dtype=np.float64)) / float(first.fps)
    animation_record = _animation(builder, name, times, tracks, joint_nodes, morph_nodes,
                                  frames)
    inverse_bind = builder.add(
        tracks.inverse_bind.transpose(0, 2, 1).reshape(-1, 16).astype(np.float32), "MAT4")
    document = pygltflib.GLTF2(
        asset=pygltflib.Asset(version="2.0", generator="gnngarment"),
        scene=0, scenes=[pygltflib.Scene(name=name, nodes=scene_nodes)], nodes=nodes,
        meshes=meshes, materials=materials,
        skins=[pygltflib.Skin(name=f"{name}_skeleton", joints=joint_nodes, skeleton=0,
                              inverseBindMatrices=inverse_bind)],
        animations=[animation_record], accessors=builder.accessors,
        bufferViews=builder.views, buffers=[pygltflib.Buffer(byteLength=builder.size)])
    document.set_binary_blob(builder.blob())
    data = b"".join(document.save_to_bytes())
    atomic_write_bytes(path, data)

    max_error = mean_error = None
    if verify:
        glb = read_glb(path)
        distances = [np.linalg.norm(evaluate_mesh_node(glb, node, builder.arrays["times"])
                                    - expected, axis=-1).ravel()
                     for node, expected in garment_nodes]
        every = np.concatenate(distances)
        max_error, mean_error = float(every.max()), float(every.mean())
    skin_errors = np.concatenate(skin_only)
    return GlbExport(
        path=path, num_frames=frames, max_influences=max_influences, max_error=max_error,
        mean_error=mean_error, skin_only_max_error=float(skin_errors.max()),
        skin_only_mean_error=float(skin_errors.mean()), max_residual=residual_max,
        ill_conditioned=ill_conditioned, num_bytes=len(data), seam_vertices=seams,
        start_time=float(builder.arrays["times"][0]))


# --------------------------------------------------------------------------- pieces


def _float32_tracks(tracks: SkeletonAnimation) -> SkeletonAnimation:
    """The tracks rounded as stored: float32, quaternions renormalised in float32."""
    rotations = tracks.rotations.astype(np.float32)
    rotations /= np.linalg.norm(rotations, axis=-1, keepdims=True)
    return SkeletonAnimation(
        rest_translations=tracks.rest_translations.astype(np.float32).astype(np.float64),
        inverse_bind=tracks.inverse_bind.astype(np.float32).astype(np.float64),
        translations=tracks.translations.astype(np.float32).astype(np.float64),
        rotations=rotations.astype(np.float64), parents=tracks.parents)


def _one_hot(size: int, index: int) -> np.ndarray:
    out = np.zeros(size, dtype=np.float32)
    out[index] = 1.0
    return out


def _material(name: str, colour: tuple[float, ...], double_sided: bool):
    import pygltflib

    return pygltflib.Material(
        name=name, doubleSided=double_sided,
        pbrMetallicRoughness=pygltflib.PbrMetallicRoughness(
            baseColorFactor=list(colour), metallicFactor=0.0, roughnessFactor=0.85))


def _unit_normals(pos: np.ndarray, faces: np.ndarray, fallback: np.ndarray | None = None
                  ) -> np.ndarray:
    """Vertex normals; vertices without one get ``fallback`` (or +Y), so every stored
    normal is unit length as the spec requires."""
    normals = vertex_normals(pos, faces)
    missing = np.linalg.norm(normals, axis=1) < 0.5
    if missing.any():
        normals[missing] = (fallback[missing] if fallback is not None
                            else np.array([0.0, 1.0, 0.0]))
    return normals


def _garment_primitive(builder: _Builder, rest: np.ndarray, faces: np.ndarray,
                       offsets: np.ndarray, skin: StaticSkin, normals: bool,
                       split: SeamSplit | None = None, material: int = 0):
    """The skinned, morph-targeted garment; with ``split``, over the seam-split vertices
    (normals are computed on the unsplit mesh, so seams stay smooth)."""
    import pygltflib

    source = np.arange(len(rest)) if split is None else split.source
    count = len(source)
    attributes = pygltflib.Attributes(
        POSITION=builder.add(rest[source].astype(np.float32), "VEC3", bounds=True,
                             target=ARRAY_BUFFER))
    base_normals = None
    if normals:
        base_normals = _unit_normals(rest, faces).astype(np.float32)
        attributes.NORMAL = builder.add(base_normals[source], "VEC3", target=ARRAY_BUFFER)
    if split is not None:
        flipped = np.stack([split.uv[:, 0], 1.0 - split.uv[:, 1]], axis=1)  # glTF v is down
        attributes.TEXCOORD_0 = builder.add(flipped.astype(np.float32), "VEC2",
                                            target=ARRAY_BUFFER)
    padded = -(-skin.joints.shape[1] // 4) * 4
    joints = np.zeros((count, padded), dtype=np.uint8)
    weights = np.zeros((count, padded), dtype=np.float32)
    joints[:, :skin.joints.shape[1]] = skin.joints[source]
    weights[:, :skin.weights.shape[1]] = skin.weights[source]
    for n in range(padded // 4):
        setattr(attributes, f"JOINTS_{n}", builder.add(joints[:, 4 * n:4 * n + 4], "VEC4",
                                                       target=ARRAY_BUFFER))
        setattr(attributes, f"WEIGHTS_{n}", builder.add(weights[:, 4 * n:4 * n + 4], "VEC4",
                                                        target=ARRAY_BUFFER))
    targets = []
    for offset in offsets:
        target = {"POSITION": builder.add(offset[source].astype(np.float32), "VEC3",
                                          bounds=True, target=ARRAY_BUFFER)}
        if base_normals is not None:
            moved = _unit_normals(rest + offset, faces, base_normals)
            target["NORMAL"] = builder.add((moved - base_normals)[source].astype(np.float32),
                                           "VEC3", target=ARRAY_BUFFER)
        targets.append(target)
    split_faces = faces if split is None else split.faces
    return pygltflib.Primitive(attributes=attributes,
                               indices=_indices(builder, split_faces, count),
                               targets=targets, material=material, mode=4)


def _morph_only_primitive(builder: _Builder, frames: np.ndarray, faces: np.ndarray,
                          material: int = 1):
    """Frame 0 as the base mesh, frame ``t − frame 0`` as target ``t`` (flat shaded)."""
    import pygltflib

    base = frames[0].astype(np.float32)
    attributes = pygltflib.Attributes(POSITION=builder.add(base, "VEC3", bounds=True,
                                                           target=ARRAY_BUFFER))
    targets = [{"POSITION": builder.add((frame - base).astype(np.float32), "VEC3",
                                        bounds=True, target=ARRAY_BUFFER)} for frame in frames]
    return pygltflib.Primitive(attributes=attributes,
                               indices=_indices(builder, faces, len(base)), targets=targets,
                               material=material, mode=4)


def _indices(builder: _Builder, faces: np.ndarray, count: int) -> int:
    dtype = np.uint16 if count <= 65535 else np.uint32
    return builder.add(faces.reshape(-1, 1).astype(dtype), "SCALAR",
                       target=ELEMENT_ARRAY_BUFFER)


def _skeleton_nodes(tracks: SkeletonAnimation) -> tuple[list, list[int]]:
    """Joint nodes 0..23 in skeleton order (node index = joint index)."""
    import pygltflib

    nodes = [pygltflib.Node(name=JOINT_NAMES[j],
                            translation=[float(v) for v in tracks.rest_translations[j]])
             for j in range(len(tracks.parents))]
    for j, parent in enumerate(tracks.parents):
        if parent >= 0:
            nodes[parent].children.append(j)
    return nodes, list(range(len(tracks.parents)))


def _animation(builder: _Builder, name: str, times: np.ndarray, tracks: SkeletonAnimation,
               joint_nodes: list[int], morph_nodes: list[tuple[int, str]], frames: int):
    import pygltflib

    time_accessor = builder.add(times.astype(np.float32).reshape(-1, 1), "SCALAR", bounds=True)
    builder.arrays["times"] = times.astype(np.float32).astype(np.float64)
    samplers, channels = [], []

    def channel(node: int, path: str, values: np.ndarray, kind: str,
                interpolation: str = "LINEAR") -> None:
        output = builder.add(values.astype(np.float32), kind)
        samplers.append(pygltflib.AnimationSampler(input=time_accessor, output=output,
                                                   interpolation=interpolation))
        channels.append(pygltflib.AnimationChannel(
            sampler=len(samplers) - 1,
            target=pygltflib.AnimationChannelTarget(node=node, path=path)))

    for j, node in enumerate(joint_nodes):
        channel(node, "translation", tracks.translations[:, j], "VEC3")
        channel(node, "rotation", tracks.rotations[:, j], "VEC4")
    # One-hot weights: keyframe t switches morph target t fully on (T × T values).
    one_hot = np.eye(frames, dtype=np.float32).reshape(-1, 1)
    for node, interpolation in morph_nodes:
        channel(node, "weights", one_hot, "SCALAR", interpolation)
    return pygltflib.Animation(name=name, samplers=samplers, channels=channels)


class _Builder:
    """Collects arrays into one binary buffer: one 4-byte-aligned bufferView and one
    accessor per array."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.size = 0
        self.views: list = []
        self.accessors: list = []
        self.arrays: dict[str, np.ndarray] = {}

    def add(self, array: np.ndarray, kind: str, bounds: bool = False,
            target: int | None = None) -> int:
        import pygltflib

        component = {np.dtype(np.float32): FLOAT, np.dtype(np.uint8): UNSIGNED_BYTE,
                     np.dtype(np.uint16): UNSIGNED_SHORT,
                     np.dtype(np.uint32): UNSIGNED_INT}[array.dtype]
        data = np.ascontiguousarray(array, dtype=array.dtype.newbyteorder("<")).tobytes()
        self.views.append(pygltflib.BufferView(buffer=0, byteOffset=self.size,
                                               byteLength=len(data), target=target))
        padding = -len(data) % 4
        self.parts.append(data + b"\0" * padding)
        self.size += len(data) + padding
        accessor = pygltflib.Accessor(bufferView=len(self.views) - 1, componentType=component,
                                      count=len(array), type=kind)
        if bounds:
            # Exact float32 extremes: the validator compares them with the data bit for bit.
            accessor.min = [float(v) for v in array.min(axis=0)]
            accessor.max = [float(v) for v in array.max(axis=0)]
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def blob(self) -> bytes:
        return b"".join(self.parts)
