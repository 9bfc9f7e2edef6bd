"""CLOTH3D reader and writer: point caches, ``info.mat``, sequence folders, frames.

Public API (numpy in, numpy out; ``pos (N, 3)``, ``faces (F, 3)``, ``frames (T, N, 3)``,
metres, radians):

- point caches: :func:`read_point_cache`, :func:`read_point_cache_header`,
  :func:`write_point_cache` (``.pc16`` float16, ``.pc2`` float32)
- ``info.mat``: :func:`read_info`, :func:`write_info`
- sequence folders: :func:`read_sequence`, :func:`write_sequence`,
  :func:`inspect_sequence`, :func:`scan_dataset`
- frame conventions: :func:`to_world`, :func:`from_world`, :func:`world_transform`,
  :func:`rest_to_canonical`, :func:`canonical_to_rest`, :func:`z_rotation`
  (assumed from CLOTH3D's starter kit; unverified on real data, see ``docs/cloth3d.md``)
- errors: :class:`Cloth3DError` (a ``ValueError`` whose message names the file)
"""

from data_prep.cloth3d.atomic import atomic_write
from data_prep.cloth3d.errors import Cloth3DError
from data_prep.cloth3d.frames import (
    canonical_to_rest,
    from_world,
    rest_to_canonical,
    to_world,
    world_transform,
    z_rotation,
)
from data_prep.cloth3d.info import read_info, write_info
from data_prep.cloth3d.obj_file import write_obj
from data_prep.cloth3d.point_cache import (
    PointCacheHeader,
    read_point_cache,
    read_point_cache_header,
    write_point_cache,
)
from data_prep.cloth3d.scan import scan_dataset
from data_prep.cloth3d.sequence import (
    DEFAULT_FPS,
    GARMENT_NAMES,
    Cloth3DGarment,
    Cloth3DSequence,
    GarmentFiles,
    SequenceLayout,
    inspect_sequence,
    read_sequence,
    write_sequence,
)

__all__ = [
    "DEFAULT_FPS", "GARMENT_NAMES", "Cloth3DError", "Cloth3DGarment", "Cloth3DSequence",
    "GarmentFiles", "PointCacheHeader", "SequenceLayout", "atomic_write", "canonical_to_rest",
    "from_world", "inspect_sequence", "read_info", "read_point_cache",
    "read_point_cache_header", "read_sequence", "rest_to_canonical", "scan_dataset",
    "to_world", "world_transform", "write_info", "write_obj", "write_point_cache",
    "write_sequence", "z_rotation",
]
