"""A CLOTH3D sequence folder: ``info.mat`` + ``<Garment>.obj`` + ``<Garment>.pc16``.

Reading checks everything that can be checked from headers first
(:func:`inspect_sequence`, also used by :func:`~data_prep.cloth3d.scan.scan_dataset`),
then loads meshes and payloads; any inconsistency is a :class:`Cloth3DError`, never a
partial sequence. Writing produces the same layout, so the synthetic dataset and real
CLOTH3D go through one reader.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from data_prep.cloth3d.errors import Cloth3DError, point_cache_errors
from data_prep.cloth3d.frames import to_world
from data_prep.cloth3d.info import GENDER_NAMES, normalise_info, read_info, write_info
from data_prep.cloth3d.rest_alignment import RestAlignment, rest_alignment
from gnngarment.io import point_cache
from gnngarment.io.obj import count_obj_vertices, write_obj
from gnngarment.io.point_cache import (
    FLOAT16_MAX,
    PointCacheHeader,
    read_payload,
    write_point_cache,
)

INFO_FILE = "info.mat"
#: Garment names in the CLOTH3D release (a folder may use any subset; others are allowed).
GARMENT_NAMES = ("Top", "Tshirt", "Trousers", "Skirt", "Jumpsuit", "Dress")
#: Point cache extensions, in the order they are looked for.
CACHE_EXTENSIONS = (".pc16", ".pc2")
DEFAULT_FPS = 30.0  # not stored in CLOTH3D files; an assumption, configurable


def read_point_cache_header(path: str | Path, half: bool | None = None) -> PointCacheHeader:
    """:func:`gnngarment.io.point_cache.read_point_cache_header`, raising CLOTH3D's error.

    Raises:
        Cloth3DPointCacheError: as the library function (message ``<path>: <problem>``);
            a :class:`Cloth3DError` and a ``PointCacheError``.
    """
    with point_cache_errors():
        return point_cache.read_point_cache_header(path, half)


def read_point_cache(path: str | Path, half: bool | None = None,
                     frames: slice | None = None) -> np.ndarray:
    """:func:`gnngarment.io.point_cache.read_point_cache`: ``(T, N, 3)`` float32
    positions, raising CLOTH3D's error.

    Raises:
        Cloth3DPointCacheError: as the library function.
    """
    with point_cache_errors():
        return point_cache.read_point_cache(path, half, frames)


class Cloth3DGarment(NamedTuple):
    """One garment of a sequence; unpacks as ``rest_pos, faces, frames``.

    Attributes:
        rest_pos: ``(N, 3)`` float64 rest mesh as stored in the OBJ: canonical (no
            ``trans``, no ``zrot``; root at the origin, Z up), metres.
        faces: ``(F, 3)`` int64 triangles (quads of the OBJ split).
        frames: ``(T, N, 3)`` float32 positions in the cache frame (root at the origin,
            before ``trans`` and ``zrot``; see :mod:`data_prep.cloth3d.frames`), metres.
    """

    rest_pos: np.ndarray
    faces: np.ndarray
    frames: np.ndarray


@dataclass(frozen=True)
class Cloth3DSequence:
    """A fully loaded, consistent CLOTH3D sequence.

    Attributes:
        name: the folder name (CLOTH3D sample id, e.g. ``"01_01_s0"`` or ``"00042"``).
        folder: the sequence folder.
        info: :func:`~data_prep.cloth3d.info.read_info` of ``info.mat``.
        fps: frames per second (not in the files; 30 assumed unless told).
        garments: garment name → :class:`Cloth3DGarment`, in ``outfit`` order.
    """

    name: str
    folder: Path
    info: dict[str, Any]
    fps: float
    garments: dict[str, Cloth3DGarment] = field(default_factory=dict)

    @property
    def num_frames(self) -> int:
        """``T``, shared by ``poses``, ``trans`` and every garment's frames."""
        return len(self.info["poses"])

    @property
    def poses(self) -> np.ndarray:
        """``(T, 72)`` SMPL axis-angle pose parameters, radians."""
        return self.info["poses"]

    @property
    def joint_rotations(self) -> np.ndarray:
        """``(T, 24, 3)`` local axis-angle rotations in SMPL joint order, radians."""
        return self.info["poses"].reshape(-1, 24, 3)

    @property
    def trans(self) -> np.ndarray:
        """``(T, 3)`` root translation, metres (applied before ``zrot``)."""
        return self.info["trans"]

    @property
    def shape(self) -> np.ndarray:
        """``(10,)`` SMPL shape parameters (betas)."""
        return self.info["shape"]

    @property
    def gender(self) -> int:
        """0 female, 1 male (selects the SMPL model)."""
        return self.info["gender"]

    @property
    def gender_name(self) -> str:
        """``"female"`` or ``"male"``, the SMPL model to pose this sequence with.

        Raises:
            Cloth3DError: ``gender`` is neither 0 nor 1 (names ``info.mat``).
        """
        if self.gender not in (0, 1):
            raise Cloth3DError(f"{self.folder / INFO_FILE}: gender = {self.gender}, expected "
                               f"0 (female) or 1 (male)")
        return GENDER_NAMES[self.gender]

    @property
    def zrot(self) -> float:
        """Rotation of the whole sequence about +z, radians."""
        return self.info["zrot"]

    def world_frames(self, garment: str) -> np.ndarray:
        """``(T, N, 3)`` float32 world positions of ``garment``: ``R_z(zrot)(x + trans_t)``."""
        return to_world(self.garments[garment].frames, self.trans, self.zrot)

    def rest_alignment(self, garment: str) -> RestAlignment:
        """How well ``garment``'s rest mesh matches its frames with each frame's root
        rotation undone (:func:`~data_prep.cloth3d.rest_alignment.rest_alignment`);
        ``.problem()`` is ``None`` when they are consistent."""
        rest_pos, _, frames = self.garments[garment]
        return rest_alignment(rest_pos, frames, self.joint_rotations[:, 0])


@dataclass(frozen=True)
class GarmentFiles:
    """Where one garment's files are and what their headers say (payloads unread)."""

    name: str
    obj: Path
    cache: Path
    header: PointCacheHeader

    @property
    def num_vertices(self) -> int:
        """``N``, equal in the OBJ and the cache (checked)."""
        return self.header.n_points


@dataclass(frozen=True)
class SequenceLayout:
    """A sequence folder whose info, headers and sizes are consistent (payloads unread)."""

    folder: Path
    info: dict[str, Any]
    garments: dict[str, GarmentFiles]

    @property
    def num_frames(self) -> int:
        """``T`` from ``info.mat``, equal to every cache's ``n_samples`` (checked)."""
        return len(self.info["poses"])


def inspect_sequence(folder: str | Path) -> SequenceLayout:
    """Validate a sequence folder cheaply: ``info.mat``, cache headers and file sizes,
    OBJ vertex counts (``v`` lines counted, numbers not parsed); no payload is read.

    Every garment listed in ``outfit`` must have ``<Garment>.obj`` and exactly one of
    ``<Garment>.pc16`` / ``<Garment>.pc2``; files of garments not in ``outfit`` are
    ignored.

    Raises:
        Cloth3DError: the first problem found, naming the file.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise Cloth3DError(f"{folder}: sequence folder not found")
    info = read_info(folder / INFO_FILE)
    if not info["outfit"]:
        raise Cloth3DError(f"{folder / INFO_FILE}: outfit lists no garments")
    num_frames = len(info["poses"])
    garments = {}
    for name in info["outfit"]:
        obj = folder / f"{name}.obj"
        if not obj.is_file():
            raise Cloth3DError(f"{obj}: missing; garment '{name}' is listed in the outfit "
                               f"of {folder / INFO_FILE}")
        caches = [folder / f"{name}{ext}" for ext in CACHE_EXTENSIONS]
        present = [cache for cache in caches if cache.is_file()]
        if not present:
            raise Cloth3DError(f"{caches[0]}: missing (no .pc16 or .pc2); garment '{name}' is "
                               f"listed in the outfit of {folder / INFO_FILE}")
        if len(present) > 1:
            raise Cloth3DError(f"{present[0]}: ambiguous, {present[1].name} exists too; "
                               f"keep one point cache per garment")
        header = read_point_cache_header(present[0])
        try:
            num_vertices = count_obj_vertices(obj)
        except OSError as error:
            raise Cloth3DError(f"{obj}: cannot read OBJ file ({error})") from error
        if header.n_points != num_vertices:
            raise Cloth3DError(f"{header.path}: n_points = {header.n_points} but {obj.name} "
                               f"has {num_vertices} vertices")
        if header.n_samples != num_frames:
            raise Cloth3DError(f"{header.path}: {header.n_samples} frames but poses/trans in "
                               f"{INFO_FILE} have {num_frames}")
        garments[name] = GarmentFiles(name, obj, header.path, header)
    return SequenceLayout(folder, info, garments)


def read_sequence(folder: str | Path, fps: float = DEFAULT_FPS) -> Cloth3DSequence:
    """Read a CLOTH3D sequence folder completely, or fail.

    Args:
        folder: holds ``info.mat``, ``<Garment>.obj`` and ``<Garment>.pc16`` (or ``.pc2``).
        fps: frame rate to attach (CLOTH3D does not store one).

    Returns:
        The sequence; rest meshes as stored (CLOTH3D stores them canonical: measured on
        real data, see :mod:`data_prep.cloth3d.frames`), frames in the cache frame (see
        :meth:`Cloth3DSequence.world_frames`). Nothing checks that the two agree; see
        :meth:`Cloth3DSequence.rest_alignment`.

    Raises:
        Cloth3DError: anything :func:`inspect_sequence` finds, an unreadable OBJ, or an
            OBJ whose faces index missing vertices.
        ValueError: ``fps`` is not positive.
    """
    from gnngarment.geometry import MeshError, load_mesh

    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be positive, got {fps}")
    layout = inspect_sequence(folder)
    garments = {}
    for name, files in layout.garments.items():
        try:
            pos, faces = load_mesh(files.obj)
        except MeshError as error:
            raise Cloth3DError(str(error)) from error
        if len(pos) != files.num_vertices:  # e.g. the file changed since inspection
            raise Cloth3DError(f"{files.cache}: n_points = {files.num_vertices} but "
                               f"{files.obj.name} has {len(pos)} vertices")
        if faces.size and (faces.min() < 0 or faces.max() >= len(pos)):
            raise Cloth3DError(f"{files.obj}: face indices span [{faces.min() + 1}, "
                               f"{faces.max() + 1}] (1-based) but there are {len(pos)} "
                               f"vertices")
        with point_cache_errors():
            frames = read_payload(files.header)
        garments[name] = Cloth3DGarment(pos, faces, frames)
    return Cloth3DSequence(layout.folder.name, layout.folder, layout.info, float(fps), garments)


def write_sequence(folder: str | Path, info: Mapping[str, Any],
                   garments: Mapping[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
                   half: bool = True) -> Path:
    """Write a sequence folder in CLOTH3D's layout, each file atomically.

    Writes ``<Garment>.obj`` (the canonical rest mesh as given, as CLOTH3D stores it),
    ``<Garment>.pc16`` (or ``.pc2`` with ``half=False``; a stale cache of the other kind
    is removed so the reader never sees two) and, last, ``info.mat``. An existing
    ``info.mat`` is removed before anything else is written, so a folder whose writing
    was interrupted has no ``info.mat`` and fails inspection instead of silently mixing
    old and new files.

    Args:
        folder: created if missing.
        info: fields as :func:`~data_prep.cloth3d.info.write_info` takes them; ``outfit``
            must name exactly the garments given.
        garments: name → ``(rest_pos (N, 3) canonical, faces (F, 3), frames (T, N, 3)
            cache frame)``, metres; a :class:`Cloth3DGarment` works as is.
        half: float16 ``.pc16`` (CLOTH3D's choice) or float32 ``.pc2``.

    Returns:
        ``folder`` as a :class:`~pathlib.Path`.

    Raises:
        ValueError: inconsistent inputs (checked before anything is written).
    """
    folder = Path(folder)
    normalised = normalise_info(info, stored=False)
    outfit = list(normalised["outfit"])
    if not garments or set(outfit) != set(garments):
        raise ValueError(f"{folder}: outfit lists {sorted(outfit)} but garments given are "
                         f"{sorted(garments)}; they must match")
    num_frames = len(normalised["poses"])
    checked = {}
    for name in outfit:
        rest_pos, faces, frames = (np.asarray(a) for a in garments[name])
        if rest_pos.ndim != 2 or rest_pos.shape[1] != 3:
            raise ValueError(f"{folder}: {name} rest_pos has shape {rest_pos.shape}, "
                             f"expected (N, 3)")
        if frames.shape != (num_frames, len(rest_pos), 3):
            raise ValueError(f"{folder}: {name} frames have shape {frames.shape}, expected "
                             f"(T, N, 3) = ({num_frames}, {len(rest_pos)}, 3)")
        if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer) \
                or (faces.size and (faces.min() < 0 or faces.max() >= len(rest_pos))):
            raise ValueError(f"{folder}: {name} faces must be (F, 3) integers in "
                             f"[0, {len(rest_pos) - 1}], got shape {faces.shape}")
        if not (np.isfinite(rest_pos).all() and np.isfinite(frames).all()):
            raise ValueError(f"{folder}: {name} positions contain NaN or inf")
        if half and frames.size and np.abs(frames).max() > FLOAT16_MAX:
            raise ValueError(f"{folder}: {name} frames overflow float16; use half=False")
        checked[name] = (rest_pos, faces, frames)

    folder.mkdir(parents=True, exist_ok=True)
    # An old info.mat goes first and the new one comes last, so an interrupted rewrite
    # leaves a folder that fails inspection rather than one mixing old and new files.
    with contextlib.suppress(FileNotFoundError):
        os.unlink(folder / INFO_FILE)
    extension, other = (".pc16", ".pc2") if half else (".pc2", ".pc16")
    for name, (rest_pos, faces, frames) in checked.items():
        write_obj(folder / f"{name}.obj", rest_pos, faces)
        write_point_cache(folder / f"{name}{extension}", frames, half=half)
        with contextlib.suppress(FileNotFoundError):
            os.unlink(folder / f"{name}{other}")
    write_info(folder / INFO_FILE, normalised)
    return folder
