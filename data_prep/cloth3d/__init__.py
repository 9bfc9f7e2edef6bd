"""CLOTH3D reader and writer: point caches, ``info.mat``, sequence folders, frames.

Public API (numpy in, numpy out; ``pos (N, 3)``, ``faces (F, 3)``, ``frames (T, N, 3)``,
metres, radians):

- point caches: :func:`read_point_cache`, :func:`read_point_cache_header`,
  :func:`write_point_cache` (``.pc16`` float16, ``.pc2`` float32;
  :mod:`gnngarment.io.point_cache`, its read errors raised as :class:`Cloth3DError`)
- ``info.mat``: :func:`read_info`, :func:`write_info`
- sequence folders: :func:`read_sequence`, :func:`write_sequence`,
  :func:`inspect_sequence`, :func:`scan_dataset`
- frame conventions: :func:`to_world`, :func:`from_world`, :func:`world_transform`,
  :func:`z_rotation` (measured on a real sequence, see ``docs/cloth3d.md``); rest OBJs
  are stored canonical and read as they are
- rest template vs frames: :func:`rest_alignment`, :func:`unroot_frames`,
  :class:`RestAlignment`
- OBJ: :func:`write_obj` (:mod:`gnngarment.io.obj`)
- errors: :class:`Cloth3DError` (a ``ValueError`` whose message names the file)
"""

from data_prep.cloth3d.errors import Cloth3DError
from data_prep.cloth3d.frames import from_world, to_world, world_transform, z_rotation
from data_prep.cloth3d.info import GENDER_NAMES, read_info, write_info
from data_prep.cloth3d.rest_alignment import RestAlignment, rest_alignment, unroot_frames
from data_prep.cloth3d.scan import scan_dataset
from data_prep.cloth3d.sequence import (
    DEFAULT_FPS,
    GARMENT_NAMES,
    Cloth3DGarment,
    Cloth3DSequence,
    GarmentFiles,
    SequenceLayout,
    inspect_sequence,
    read_point_cache,
    read_point_cache_header,
    read_sequence,
    write_sequence,
)
from gnngarment.io.atomic import atomic_write
from gnngarment.io.obj import write_obj
from gnngarment.io.point_cache import PointCacheHeader, write_point_cache

__all__ = [
    "DEFAULT_FPS", "GARMENT_NAMES", "GENDER_NAMES", "Cloth3DError", "Cloth3DGarment",
    "Cloth3DSequence", "GarmentFiles", "PointCacheHeader", "RestAlignment", "SequenceLayout",
    "atomic_write", "from_world", "inspect_sequence", "read_info", "read_point_cache",
    "read_point_cache_header", "read_sequence", "rest_alignment", "scan_dataset", "to_world",
    "unroot_frames", "world_transform", "write_info", "write_obj", "write_point_cache",
    "write_sequence", "z_rotation",
]
