"""Export an animated garment: OBJ sequence, PC2 point cache, glTF binary, GIF preview.

Public API (numpy in, files out; ``posed (T, N, 3)`` metres, Z up):

- everything at once: :func:`export_animation` (folder layout in ``docs/export.md``)
- OBJ: :func:`write_obj_sequence`, :func:`write_obj` (input vertex order kept; the
  writer is :mod:`gnngarment.io.obj`'s)
- point caches: :func:`write_point_cache`, :func:`read_point_cache`,
  :func:`read_point_cache_header` (``.pc2`` float32, ``.pc16`` float16; from
  :mod:`gnngarment.io.point_cache`)
- glTF: :func:`write_glb` (skinned + morph targets), :func:`read_glb`,
  :func:`evaluate_mesh_node` (what a viewer shows, in numpy)
- preview: :func:`render_preview` (GIF)

Names are resolved on first use (PEP 562), so the point-cache and OBJ names load only
:mod:`gnngarment.io`: neither torch nor matplotlib.
"""

from __future__ import annotations

import importlib
from typing import Any

_MODULES = {
    "DEFAULT_FORMATS": "export", "FORMATS": "export", "export_animation": "export",
    "GLTF_FROM_WORLD": "gltf", "GlbExport": "gltf", "write_glb": "gltf",
    "evaluate_mesh_node": "gltf_reader", "read_glb": "gltf_reader",
    "write_obj": "gnngarment.io.obj", "write_obj_sequence": "obj_sequence",
    "PointCacheError": "gnngarment.io.point_cache",
    "PointCacheHeader": "gnngarment.io.point_cache",
    "read_point_cache": "gnngarment.io.point_cache",
    "read_point_cache_header": "gnngarment.io.point_cache",
    "write_point_cache": "gnngarment.io.point_cache",
    "render_preview": "preview",
}

__all__ = sorted(_MODULES)


def __getattr__(name: str) -> Any:
    module = _MODULES.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    # A bare name is a module of this package; a dotted one is absolute (gnngarment.io).
    value = getattr(importlib.import_module(module if "." in module else f"{__name__}.{module}"),
                    name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_MODULES])
