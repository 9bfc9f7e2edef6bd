"""Write an animated outfit into one folder (``export_outfit``).

Layout of ``out_dir`` for garments ``top`` and ``trousers`` and ``name="outfit"``::

    outfit.glb             one skinned, morph-animated mesh per garment on one skeleton
                           (+ the body as a morph-only mesh with include_body)
    outfit.gif             preview of every garment on the body
    outfit_export.json     manifest: garments (inner first), frames, fps, files
    top.pc2, top_rest.obj, top_obj/ …      each garment as a single export writes it
    trousers.pc2, …                        (export_animation, OBJ and PC2 only), in its
                                           file's vertex order; the body once, with the
                                           innermost garment (``<inner>_body.pc2`` …)
"""

from __future__ import annotations

import json
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gnngarment.inference.export.export import DEFAULT_FORMATS, FORMATS, Progress, export_animation
from gnngarment.inference.export.gltf import write_outfit_glb
from gnngarment.inference.export.preview import render_preview
from gnngarment.io.atomic import FolderLock, atomic_write_bytes

if TYPE_CHECKING:
    from gnngarment.inference.animate import Animation
    from gnngarment.inference.outfit import OutfitAnimation


def merged_animation(animations: list[Animation]) -> Animation:
    """All garments of an outfit as one :class:`Animation` (vertices concatenated, faces
    renumbered; UVs dropped): what the outfit's preview draws."""
    offsets = np.cumsum([0] + [len(animation.rest_pos) for animation in animations])
    first = animations[0]
    return replace(
        first, rest_pos=np.concatenate([a.rest_pos for a in animations]),
        faces=np.concatenate([np.asarray(a.faces) + offset
                              for a, offset in zip(animations, offsets, strict=False)]),
        posed=np.concatenate([a.posed for a in animations], axis=1),
        weights=np.concatenate([a.weights for a in animations], axis=1),
        blend_shapes=np.concatenate([a.blend_shapes for a in animations], axis=1),
        raw_posed=None, raw_rest_pos=None, uv=None, uv_faces=None)


def outfit_paths(out_dir: str | Path, name: str, formats) -> list[Path]:
    """The outfit-level files :func:`export_outfit` writes (the garments' own files are
    :func:`~gnngarment.inference.export.export.export_paths` of each name)."""
    out = Path(out_dir)
    files = [out / f"{name}_export.json"]
    files += [out / f"{name}.{kind}" for kind in ("glb", "gif", "mp4") if kind in formats]
    return files


def export_outfit(outfit: OutfitAnimation, out_dir: str | Path, name: str = "outfit",
                  formats: tuple[str, ...] | list[str] = DEFAULT_FORMATS,
                  include_body: bool = True, progress: Progress | None = None, *,
                  max_influences: int = 4, lock: FolderLock | None = None
                  ) -> dict[str, Path]:
    """Export an outfit: its glb and preview under ``name``, each garment's OBJ and PC2
    under the garment's name.

    Args:
        outfit: the prediction (:func:`~gnngarment.inference.outfit.animate_outfit`).
        out_dir: output folder (created).
        name: stem of the outfit's glb, preview and manifest; must differ from every
            garment's name.
        formats: as :func:`~gnngarment.inference.export.export.export_animation`.
        include_body: as ``export_animation`` (the body goes with the innermost garment).
        progress: as ``export_animation``.
        max_influences: as ``export_animation``.
        lock: as ``export_animation``.

    Returns:
        Paths by key: ``"glb"``, ``"gif"``/``"mp4"``, ``"manifest"`` and
        ``"<garment>:<key>"`` for each garment's files.

    Raises:
        ValueError: unknown format, a name shared with a garment, or inconsistent arrays.
    """
    unknown = sorted(set(formats) - set(FORMATS))
    if unknown or not formats:
        raise ValueError(f"formats must be a non-empty subset of {FORMATS}, got {formats}")
    if name in outfit.names:
        raise ValueError(f"the outfit's name {name!r} is also a garment's")
    out = Path(out_dir)
    order = [outfit.names[index] for index in outfit.order]
    inner = outfit.order[0]
    paths: dict[str, Path] = {}
    with nullcontext(lock) if lock is not None else FolderLock(out, "export") as lock:
        per_garment = [kind for kind in formats if kind in ("obj", "pc2")]
        for index in outfit.order:
            if not per_garment:
                break
            garment = outfit.names[index]
            written = export_animation(outfit.animations[index], out, garment,
                                       formats=per_garment,
                                       include_body=include_body and index == inner,
                                       progress=progress, lock=lock,
                                       max_influences=max_influences)
            paths.update({f"{garment}:{key}": path for key, path in written.items()})
        ordered = [(outfit.names[index], outfit.animations[index]) for index in outfit.order]
        manifest: dict = {
            "name": name, "garments": order, "layers": "innermost first",
            "frames": len(outfit.animations[0].posed), "fps": float(outfit.animations[0].fps),
            "first_frame": 0, "units": "metres",
            "penetration_percent": {
                outfit.names[index]: {"raw": 100 * float(np.mean(outfit.penetration_raw[index])),
                                      "resolved": 100 * float(np.mean(outfit.penetration[index]))}
                for index in outfit.penetration},
        }
        if "glb" in formats:
            result = write_outfit_glb(ordered, out / f"{name}.glb", name=name,
                                      max_influences=max_influences, include_body=include_body)
            paths["glb"] = result.path
            manifest["glb"] = {"max_error_mm": 1000 * (result.max_error or 0.0),
                               "bytes": result.num_bytes}
            if progress is not None:
                progress("glb", 1, 1)
        for preview in ("gif", "mp4"):
            if preview in formats:
                paths[preview] = render_preview(
                    merged_animation([animation for _, animation in ordered]),
                    out / f"{name}.{preview}", include_body=include_body,
                    progress=None if progress is None
                    else (lambda done, total, kind=preview: progress(kind, done, total)),
                    garment_faces=[len(animation.faces) for _, animation in ordered])
        manifest["files"] = {key: path.name if path.parent == out else
                             str(path.relative_to(out)) for key, path in paths.items()}
        paths["manifest"] = atomic_write_bytes(out / f"{name}_export.json",
                                               json.dumps(manifest, indent=2).encode())
    return paths
