"""Write every export of an animated garment into one folder (``export_animation``).

Layout of ``out_dir`` for ``name="skirt"`` (each file written atomically)::

    skirt.glb              skinned garment + skeleton animation + per-frame morph targets
                           (+ the body as a morph-only mesh with include_body)
    skirt.pc2              garment point cache, float32, input vertex order
    skirt_rest.obj         the garment rest mesh the .pc2 applies to (same vertex order)
    skirt_body.pc2         body point cache            (include_body)
    skirt_body.obj         body base mesh, first frame (include_body)
    skirt_obj/garment_0000.obj …   one OBJ per frame   (body_0000.obj … with include_body)
    skirt.gif              preview
    skirt_export.json      manifest: frames, fps, numbering, files, glb error

``Animation.posed[0]`` is frame ``first_frame`` (0) in every format: the OBJ names, the
``.pc2`` header and the glb, whose frame ``k`` is keyed at ``(first_frame + k) / fps`` s
(Blender's glTF importer puts time ``t`` at scene frame ``t · fps``). The garment OBJs
(sequence and rest mesh) and the glb carry the input's UVs (``Animation.uv``).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from contextlib import nullcontext, suppress
from numbers import Integral
from pathlib import Path
from typing import TYPE_CHECKING

from gnngarment.inference.export.gltf import write_glb
from gnngarment.inference.export.obj_sequence import frame_path, write_obj_sequence
from gnngarment.inference.export.preview import render_preview
from gnngarment.inference.export.validation import check_animation
from gnngarment.io.atomic import FolderLock, atomic_write_bytes
from gnngarment.io.obj import write_obj
from gnngarment.io.point_cache import write_point_cache

if TYPE_CHECKING:
    from gnngarment.inference.animate import Animation

FORMATS = ("obj", "pc2", "glb", "gif", "mp4")
DEFAULT_FORMATS = ("obj", "pc2", "glb", "gif")

#: ``progress(stage, done, total)``: stage is one of :data:`FORMATS`.
Progress = Callable[[str, int, int], None]


def export_animation(animation: Animation, out_dir: str | Path, name: str,
                     formats: tuple[str, ...] | list[str] = DEFAULT_FORMATS,
                     include_body: bool = True, progress: Progress | None = None, *,
                     first_frame: int = 0, max_influences: int = 4,
                     morph_interpolation: str = "LINEAR", preview_size: int = 288,
                     preview_max_frames: int = 48,
                     lock: FolderLock | None = None) -> dict[str, Path]:
    """Export an animation in the requested formats.

    Args:
        animation: the prediction (:func:`~gnngarment.inference.animate.animate`).
        out_dir: output folder (created).
        name: file stem, e.g. the garment's name (letters, digits, ``-``, ``_``, ``.``).
        formats: any of ``"obj"``, ``"pc2"``, ``"glb"``, ``"gif"`` (``"mp4"`` needs the
            optional ``imageio-ffmpeg``).
        include_body: also export the posed body (OBJ sequence, point cache, glb mesh,
            preview).
        progress: called as ``progress(stage, done, total)``.
        first_frame: frame number of ``posed[0]`` (≥ 0) in OBJ names, the ``.pc2``
            header and the glb (keyed at ``first_frame / fps`` s, Blender frame
            ``first_frame``). 0 keeps the glb starting at time 0, as engines expect.
        max_influences: joints per vertex in the glb skin (4, or up to 8).
        morph_interpolation: glb morph weights, ``"LINEAR"`` or ``"STEP"``.
        preview_size: preview height/width in pixels.
        preview_max_frames: the preview renders every k-th frame to stay under this.
        lock: the caller's held lock on ``out_dir`` (a command that took it before its
            inference); ``None``: the export takes one while it writes.

    Returns:
        Paths by key: ``"glb"``, ``"pc2"``, ``"rest_obj"``, ``"body_pc2"``, ``"body_obj"``,
        ``"obj"`` (the folder), ``"gif"``/``"mp4"``, ``"manifest"`` — those written.

    Raises:
        ValueError: unknown format, bad name, or an inconsistent animation.
    """
    unknown = sorted(set(formats) - set(FORMATS))
    if unknown or not formats:
        raise ValueError(f"formats must be a non-empty subset of {FORMATS}, got {formats}")
    if not name or not all(c.isalnum() or c in "-_." for c in name) or name.startswith("."):
        raise ValueError(f"name must be a plain file stem (letters, digits, - _ .), "
                         f"got {name!r}")
    if not isinstance(first_frame, Integral) or first_frame < 0:
        raise ValueError(f"first_frame must be an integer ≥ 0, got {first_frame!r}")
    check_animation(animation, body=include_body)
    out = Path(out_dir)
    # One export per folder at a time (a second is refused, naming the holder), and the
    # temporary files a killed earlier export left behind are removed first.
    if lock is not None and lock.folder.resolve() != out.resolve():
        raise ValueError(f"the lock given is on {lock.folder}, not on {out}")
    with nullcontext(lock) if lock is not None else FolderLock(out, "export") as lock:
        lock.remove_stale_temporaries((".", f"{name}_obj"))
        manifest = out / f"{name}_export.json"
        previous = _previous_frames(manifest)
        previous_files = {path.name for path in listed_export_files(out, name)}
        files, folders = export_paths(out, name, formats, include_body)
        writing = {path.name for path in [*files, *folders]}
        # Until this export ends, its manifest says which frames and files may be on disk
        # (the previous export's and this one's): an export killed part-way leaves what
        # the next one then knows to remove.
        _write_pending_manifest(manifest, name, previous, first_frame, len(animation.posed),
                                sorted(previous_files | writing))
        paths = _export(animation, out, name, formats, include_body, progress, first_frame,
                        max_influences, morph_interpolation, preview_size, preview_max_frames)
        if "obj" in formats and previous is not None:
            _remove_stale_frames(paths["obj"], previous, first_frame, len(animation.posed))
        # What an earlier export of ours (by its manifest) wrote and this one did not: a
        # killed run's skirt.glb must not sit beside a new, shorter export without one.
        for stale in sorted(previous_files - writing):
            path = out / stale
            if path.is_symlink():
                continue
            if path.is_dir():
                if previous is not None:
                    _remove_stale_frames(path, previous, 0, 0)
                with suppress(OSError):  # not empty: holds something we did not write
                    path.rmdir()
            elif path.is_file():
                path.unlink(missing_ok=True)
    return paths


def listed_export_files(out_dir: str | Path, name: str) -> list[Path]:
    """The files and folders the earlier export in ``out_dir`` lists in its manifest
    (also one killed part-way), kept only where they are names an export of ``name``
    would use (a foreign manifest cannot point elsewhere). The next export removes those
    it does not write itself, so a command checks its inputs against them too."""
    out = Path(out_dir)
    manifest = out / f"{name}_export.json"
    try:
        listed = json.loads(manifest.read_text())["files"]
        names = set(listed.values() if isinstance(listed, dict) else listed)
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return []
    files, folders = export_paths(out, name, FORMATS, include_body=True)
    ours = {path.name for path in [*files, *folders]} - {manifest.name}
    return [out / item for item in sorted(i for i in names if isinstance(i, str)) if item in ours]


def export_paths(out_dir: str | Path, name: str, formats: Sequence[str], include_body: bool
                 ) -> tuple[list[Path], list[Path]]:
    """What :func:`export_animation` writes into ``out_dir``: ``(files, folders)``, each
    folder's contents being replaced too — so a command can refuse, before any work, an
    output that would overwrite one of its inputs."""
    out = Path(out_dir)
    files = [out / f"{name}_export.json"]
    if "glb" in formats:
        files.append(out / f"{name}.glb")
    if "pc2" in formats:
        files += [out / f"{name}.pc2", out / f"{name}_rest.obj"]
        if include_body:
            files += [out / f"{name}_body.pc2", out / f"{name}_body.obj"]
    files += [out / f"{name}.{preview}" for preview in ("gif", "mp4") if preview in formats]
    folders = [out / f"{name}_obj"] if "obj" in formats else []
    return files, folders


def _previous_frames(manifest: Path) -> tuple[int, int] | None:
    """(first frame, frame count) of the export whose manifest is ``manifest``, or
    ``None`` (no manifest, or not one of ours)."""
    try:
        data = json.loads(manifest.read_text())
        return int(data["first_frame"]), int(data["frames"])
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _write_pending_manifest(manifest: Path, name: str, previous: tuple[int, int] | None,
                            first_frame: int, frames: int, files: list[str]) -> None:
    """The manifest of an export in progress: the frame range covering the previous
    export's frames and this one's, and the files of both (replaced by the full manifest
    at the end)."""
    start, end = first_frame, first_frame + frames
    if previous is not None:
        start, end = min(start, previous[0]), max(end, previous[0] + previous[1])
    atomic_write_bytes(manifest, json.dumps({
        "name": name, "first_frame": start, "frames": end - start, "in_progress": True,
        "files": files,
    }, indent=2).encode())


def _remove_stale_frames(folder: Path, previous: tuple[int, int], first_frame: int,
                         frames: int) -> None:
    """Delete the per-frame OBJs a previous export (per its manifest) wrote that this one
    did not overwrite — a shorter re-run would otherwise leave its old extra frames."""
    start, count = previous
    kept = range(first_frame, first_frame + frames)
    # Frame numbers are zero-padded to the widest number of the export that wrote them.
    widths = {4, len(str(start + count - 1))}
    # Over the files that exist, not the range the manifest claims: a foreign or edited
    # manifest claiming 10^8 frames must not make this loop for hours (issue 38).
    for path in [*folder.glob("garment_*.obj"), *folder.glob("body_*.obj")]:
        stem, _, digits_text = path.stem.rpartition("_")
        if not digits_text.isdigit():
            continue
        frame = int(digits_text)
        if (start <= frame < start + count and frame not in kept and not path.is_symlink()
                and any(frame_path(folder, stem, frame, d) == path for d in widths)):
            path.unlink(missing_ok=True)


def _export(animation: Animation, out: Path, name: str, formats, include_body: bool,
            progress: Progress | None, first_frame: int, max_influences: int,
            morph_interpolation: str, preview_size: int, preview_max_frames: int
            ) -> dict[str, Path]:
    frames = len(animation.posed)
    paths: dict[str, Path] = {}
    manifest: dict = {
        "name": name, "frames": frames, "fps": float(animation.fps),
        "first_frame": first_frame, "garment_vertices": int(animation.posed.shape[1]),
        "units": "metres", "up_axis": "Z (OBJ, PC2); Y (glb, per the glTF spec)",
        "uv": animation.uv is not None,
    }
    uv = {"uv": animation.uv, "uv_faces": animation.uv_faces}

    def report(stage: str) -> Callable[[int, int], None] | None:
        if progress is None:
            return None
        return lambda done, total: progress(stage, done, total)

    if "glb" in formats:
        result = write_glb(animation, out / f"{name}.glb", name=name,
                           max_influences=max_influences,
                           morph_interpolation=morph_interpolation, include_body=include_body,
                           first_frame=first_frame)
        paths["glb"] = result.path
        manifest["glb"] = {
            "max_influences": max_influences, "morph_interpolation": morph_interpolation,
            "max_error_mm": 1000 * result.max_error, "mean_error_mm": 1000 * result.mean_error,
            "skin_only_max_error_mm": 1000 * result.skin_only_max_error,
            "skin_only_mean_error_mm": 1000 * result.skin_only_mean_error,
            "ill_conditioned": result.ill_conditioned, "bytes": result.num_bytes,
            "start_time_s": result.start_time, "seam_vertices": result.seam_vertices}
        if progress is not None:
            progress("glb", 1, 1)
    if "pc2" in formats:
        header = {"start_frame": float(first_frame), "sample_rate": 1.0}
        paths["pc2"] = write_point_cache(out / f"{name}.pc2", animation.posed, **header)
        paths["rest_obj"] = write_obj(out / f"{name}_rest.obj", animation.rest_pos,
                                      animation.faces, header=f"{name} rest mesh (metres, Z up)",
                                      **uv)
        if include_body:
            paths["body_pc2"] = write_point_cache(out / f"{name}_body.pc2",
                                                  animation.body_vertices, **header)
            paths["body_obj"] = write_obj(out / f"{name}_body.obj", animation.body_vertices[0],
                                          animation.body_faces,
                                          header=f"{name} body, frame {first_frame}")
        if progress is not None:
            progress("pc2", 1, 1)
    if "obj" in formats:
        folder = out / f"{name}_obj"
        write_obj_sequence(folder, animation.posed, animation.faces, "garment", first_frame,
                           report("obj"), **uv)
        if include_body:
            write_obj_sequence(folder, animation.body_vertices, animation.body_faces, "body",
                               first_frame)
        paths["obj"] = folder
    for preview in ("gif", "mp4"):
        if preview in formats:
            paths[preview] = render_preview(
                animation, out / f"{name}.{preview}", size=preview_size,
                max_frames=preview_max_frames, include_body=include_body,
                progress=report(preview))
    manifest["files"] = {key: path.name for key, path in paths.items()}
    paths["manifest"] = atomic_write_bytes(out / f"{name}_export.json",
                                           json.dumps(manifest, indent=2).encode())
    return paths
