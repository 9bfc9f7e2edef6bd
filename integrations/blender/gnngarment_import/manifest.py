"""What the add-on reads from a gnngarment export, without ``bpy``.

``gnngarment animate`` writes ``<name>_export.json`` beside the files it lists (see
``gnngarment/inference/export/export.py`` and ``outfit_export.py``). This module turns
that manifest into an :class:`ExportManifest` (validated: a clear
:class:`ManifestError` for anything else), and computes what a Blender scene needs so
that the export's frames map 1:1 onto scene frames. Standard library only: it runs in
Blender's Python and in the project's, where its tests run.
"""

from __future__ import annotations

import json
import math
import re
import struct
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

#: PointCache2 header: magic, version, points, start frame, sample rate, samples.
PC2_HEADER = struct.Struct("<12siiffi")
PC2_MAGIC = b"POINTCACHE2\0"


class ManifestError(ValueError):
    """The file is not a usable gnngarment export manifest; the message says why."""


@dataclass(frozen=True)
class PointCacheMesh:
    """A base mesh and the point cache that animates it (``<garment>_rest.obj`` +
    ``<garment>.pc2``, or the body's pair)."""

    name: str
    obj: Path
    pc2: Path
    is_body: bool = False


@dataclass(frozen=True)
class ExportManifest:
    """A validated manifest.

    Attributes:
        path: the manifest file.
        name: the export's name (file stem of its glb and manifest).
        fps: frames per second of the animation.
        frames: frame count.
        first_frame: scene frame of the first pose (glb key time ``first_frame / fps``,
            ``.pc2`` header start frame, OBJ numbering).
        garments: the garment names, innermost first (one for a single export).
        is_outfit: written by an outfit export (``outfit_export.json``).
        files: the manifest's ``files`` (key → path relative to the manifest's folder).
        garment_vertices: the garment's vertex count (single exports list it).
    """

    path: Path
    name: str
    fps: float
    frames: int
    first_frame: int
    garments: tuple[str, ...]
    is_outfit: bool
    files: dict[str, str]
    garment_vertices: int | None = None

    @property
    def folder(self) -> Path:
        return self.path.parent

    @property
    def frame_range(self) -> tuple[int, int]:
        """``(frame_start, frame_end)`` of a scene that shows every frame once."""
        return frame_range(self.first_frame, self.frames)

    @property
    def body_name(self) -> str:
        """What the add-on names the body object."""
        return f"{self.name}_body"

    def file(self, key: str) -> Path:
        """The listed file ``key``, which must exist; :class:`ManifestError` otherwise."""
        if key not in self.files:
            raise ManifestError(f"{self.path.name}: the export has no {key!r} file (listed: "
                                f"{', '.join(sorted(self.files)) or 'none'}); re-run "
                                "gnngarment animate with that format")
        path = self.folder / self.files[key].replace("\\", "/")
        if not path.is_file():
            raise ManifestError(f"{self.path.name}: {self.files[key]} is listed but missing "
                                f"from {self.folder}")
        return path

    @property
    def glb(self) -> Path:
        return self.file("glb")

    def point_caches(self, include_body: bool = True) -> list[PointCacheMesh]:
        """Each garment's rest OBJ + PC2 (innermost first), then the body's if listed and
        asked for; :class:`ManifestError` when a garment's pair is not there."""
        meshes = []
        for garment in self.garments:
            prefix = f"{garment}:" if self.is_outfit else ""
            meshes.append(PointCacheMesh(garment, self.file(f"{prefix}rest_obj"),
                                         self.file(f"{prefix}pc2")))
        if include_body:
            prefixes = [f"{garment}:" for garment in self.garments] if self.is_outfit else [""]
            for prefix in prefixes:
                if f"{prefix}body_obj" in self.files and f"{prefix}body_pc2" in self.files:
                    meshes.append(PointCacheMesh(self.body_name,
                                                 self.file(f"{prefix}body_obj"),
                                                 self.file(f"{prefix}body_pc2"), is_body=True))
                    break
        return meshes


def frame_range(first_frame: int, frames: int) -> tuple[int, int]:
    """Scene ``(frame_start, frame_end)``, both inclusive: frame ``first_frame + k``
    shows pose ``k`` in the glb (key time ``(first_frame + k) / fps`` at scene rate
    ``fps``), the ``.pc2`` (Mesh Cache frame start ``first_frame``) and the OBJ names."""
    if frames < 1:
        raise ManifestError(f"an export has at least one frame, got {frames}")
    return first_frame, first_frame + frames - 1


def blender_fps(fps: float) -> tuple[int, float]:
    """Blender's ``(render.fps, render.fps_base)`` for a rate: the scene plays
    ``fps / fps_base`` frames per second and ``render.fps`` is an integer, so 30 is
    ``(30, 1.0)`` and 29.97 is ``(30, 1.001)``."""
    if not (isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0):
        raise ManifestError(f"fps must be a positive number, got {fps!r}")
    nearest = round(fps)
    if nearest >= 1 and abs(fps - nearest) <= 1e-9 * fps:
        return int(nearest), 1.0
    whole = max(1, math.ceil(fps))
    return whole, whole / fps


def importer_fps_base(fps_base: float) -> float:
    """The ``fps_base`` to hold while Blender's glTF importer runs so that it keys time
    ``t`` at frame ``t · fps / fps_base``: the importer (io_scene_gltf2, Blender 4.x/5.0,
    ``animation_node.py``/``animation_weight.py``) multiplies by ``fps · fps_base``
    instead of dividing, which is only right when ``fps_base`` is 1."""
    return 1.0 / fps_base


def base_name(name: str) -> str:
    """A Blender ID name without the ``.001`` Blender adds on a clash."""
    return re.sub(r"\.\d{3,}$", "", name)


def read_pc2_header(path: str | Path) -> tuple[int, float, float, int]:
    """``(points, start_frame, sample_rate, samples)`` of a ``.pc2``;
    :class:`ManifestError` if it is not one, or is shorter than its header says."""
    path = Path(path)
    with path.open("rb") as stream:
        raw = stream.read(PC2_HEADER.size)
    if len(raw) < PC2_HEADER.size or raw[:12] != PC2_MAGIC:
        raise ManifestError(f"{path.name}: not a PointCache2 file")
    _, _, points, start, rate, samples = PC2_HEADER.unpack(raw)
    if path.stat().st_size < PC2_HEADER.size + 12 * points * samples:
        raise ManifestError(f"{path.name}: truncated ({samples} samples of {points} points "
                            "announced)")
    return points, start, rate, samples


def load_manifest(path: str | Path) -> ExportManifest:
    """Read and validate ``<name>_export.json``; :class:`ManifestError` says what is wrong."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise ManifestError(f"{path}: cannot read it ({error.strerror or error})") from None
    try:
        data = json.loads(text)
    except ValueError as error:
        raise ManifestError(f"{path.name}: not JSON ({error})") from None
    return parse_manifest(data, path)


def parse_manifest(data: object, path: str | Path) -> ExportManifest:
    """Validate a decoded manifest (``path``: where it was read, for the file paths)."""
    path = Path(path)
    where = path.name
    if not isinstance(data, dict):
        raise ManifestError(f"{where}: expected a JSON object, got {type(data).__name__}")
    if data.get("in_progress"):
        raise ManifestError(f"{where}: the export that wrote it did not finish (still "
                            "running, or killed part-way); re-run gnngarment animate")

    def field(key: str, kinds: tuple[type, ...], what: str):
        if key not in data:
            raise ManifestError(f"{where}: missing key {key!r} ({what}); is this a "
                                "gnngarment *_export.json?")
        value = data[key]
        if isinstance(value, bool) or not isinstance(value, kinds):
            raise ManifestError(f"{where}: {key!r} must be {what}, got {value!r}")
        return value

    name = field("name", (str,), "a non-empty string")
    fps = field("fps", (int, float), "a positive number")
    frames = field("frames", (int,), "a whole number ≥ 1")
    first_frame = field("first_frame", (int,), "a whole number ≥ 0")
    files = field("files", (dict,), "an object of file names")
    if not name:
        raise ManifestError(f"{where}: 'name' must be a non-empty string")
    if not (math.isfinite(fps) and fps > 0):
        raise ManifestError(f"{where}: 'fps' must be a positive number, got {fps!r}")
    if frames < 1:
        raise ManifestError(f"{where}: 'frames' must be a whole number ≥ 1, got {frames}")
    if first_frame < 0:
        raise ManifestError(f"{where}: 'first_frame' must be a whole number ≥ 0, "
                            f"got {first_frame}")
    for key, value in files.items():
        if not isinstance(value, str) or not _inside(value):
            raise ManifestError(f"{where}: files[{key!r}] must be a file name inside the "
                                f"export folder, got {value!r}")
    is_outfit = "garments" in data
    if is_outfit:
        garments = data["garments"]
        if (not isinstance(garments, list) or not garments
                or not all(isinstance(g, str) and g for g in garments)):
            raise ManifestError(f"{where}: 'garments' must be a non-empty list of names, "
                                f"got {garments!r}")
        if len(set(garments)) != len(garments):
            raise ManifestError(f"{where}: 'garments' names a garment twice: {garments}")
    else:
        garments = [name]
    vertices = data.get("garment_vertices")
    if vertices is not None and (isinstance(vertices, bool) or not isinstance(vertices, int)
                                 or vertices < 1):
        raise ManifestError(f"{where}: 'garment_vertices' must be a whole number ≥ 1, "
                            f"got {vertices!r}")
    return ExportManifest(path=path, name=name, fps=float(fps), frames=frames,
                          first_frame=first_frame, garments=tuple(garments),
                          is_outfit=is_outfit, files=dict(files), garment_vertices=vertices)


def _inside(relative: str) -> bool:
    """A relative path that stays in the folder (no absolute path, no ``..``)."""
    relative = relative.replace("\\", "/")  # a manifest written on Windows
    path = PurePosixPath(relative)
    return bool(relative) and not path.is_absolute() and ":" not in relative and (
        ".." not in path.parts)
