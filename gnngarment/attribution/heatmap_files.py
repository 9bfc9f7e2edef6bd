"""Attribute one output of a model on a garment and write the heatmap files (PNG, PLY,
NPZ, JSON): the work behind ``gnngarment attribute``, on arrays (testable without a
body model or a command line).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from gnngarment.attribution.attribution import HEAT_CHANNELS, OUTPUTS, TARGET_KINDS
from gnngarment.attribution.colors import SCALES
from gnngarment.attribution.errors import AttributionArgumentError
from gnngarment.attribution.frame_inputs import FrameInputs
from gnngarment.attribution.influence_field import influence_field
from gnngarment.attribution.integrated_gradients import attribute
from gnngarment.attribution.ply import write_attribution_ply
from gnngarment.attribution.render import render_attribution
from gnngarment.attribution.targets import geodesic_region, largest_output_vertex
from gnngarment.data.body_inputs import BodyMotionInputs, BodyShapeInputs
from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.model.deformer import GarmentDeformer


def run_attribution(model: GarmentDeformer, pos: np.ndarray, faces: np.ndarray,
                    body: BodyShapeInputs, frames: BodyMotionInputs, out: Path, *,
                    frame_index: int | None = None, target: str = "vertex",
                    vertices: list[int] | None = None, radius: float | None = None,
                    output: str = "blend_shapes", reduction: str = "norm", n_steps: int = 50,
                    heat: str = "normal", scale: str = "linear", stem: str = "attribution",
                    source: str = "<garment>") -> dict[str, Any]:
    """Attribute one output of ``model`` on a garment and write the results to ``out``:
    ``<stem>.png`` (two views, colour bar, target marked), ``<stem>.ply`` (vertex
    colours, input vertex order), ``<stem>.npz`` (:meth:`Attribution.save`) and
    ``<stem>.json`` (the numbers, also returned).

    Args:
        model: the deformer.
        pos: ``(N, 3)`` the garment in the rest body's frame (metres, Z up).
        faces: ``(F, 3)`` its triangles.
        body: the body's shape inputs.
        frames: its posed motion's inputs.
        frame_index: frame of ``frames`` (default: the middle one).
        target: ``vertex``, ``region`` or ``all``.
        vertices: the target vertex (``vertex``; default: the vertex whose output is
            largest) or the region's vertices / centres (``region``).
        radius: for ``region``, grow ``vertices`` to every vertex within this geodesic
            distance (metres).
        output: see :func:`attribute`.
        reduction: see :func:`attribute`.
        n_steps: see :func:`attribute`.
        heat: ``normal`` (the paper's heatmap) or ``all`` channels.
        scale: colour scale of the PNG and PLY, ``linear`` or ``log``.

    Raises:
        ValueError: bad target, vertices, frame or option (names the problem);
            MeshError: unusable garment mesh.
    """
    from gnngarment.inference.animate import garment_pair

    if target not in TARGET_KINDS:
        raise ValueError(f"unknown target kind '{target}' (expected one of {TARGET_KINDS})")
    if output not in OUTPUTS:
        raise ValueError(f"unknown output '{output}' (expected one of {OUTPUTS})")
    # Checked now: these are only used after the (slow) attribution.
    if heat not in HEAT_CHANNELS:
        raise ValueError(f"unknown heat channels '{heat}' (expected one of {HEAT_CHANNELS})")
    if scale not in SCALES:
        raise ValueError(f"unknown colour scale '{scale}' (expected one of {SCALES})")
    pair = garment_pair(model, pos, faces, body, source=source)
    total = frames.motion_features.shape[0]
    frame_index = total // 2 if frame_index is None else frame_index
    frame = FrameInputs.from_motion(frames, frame_index, model.config.window)

    edge_index = pair.hierarchy.edge_index
    chosen: np.ndarray | int | None = None
    if target == "vertex":
        if vertices and len(vertices) != 1:
            raise AttributionArgumentError(
                "vertices", f"target 'vertex' takes one vertex, got {len(vertices)}")
        chosen = (vertices[0] if vertices
                  else largest_output_vertex(model, pair, frame, output))
    elif target == "region":
        if not vertices:
            raise AttributionArgumentError(
                "vertices", "target 'region' needs vertices (the region, or its centres "
                "with a radius)")
        chosen = np.asarray(vertices, dtype=np.int64)
        if radius is not None:
            if chosen.min() < 0 or chosen.max() >= len(pos):
                raise AttributionArgumentError(
                    "vertices", f"region centre out of range for a garment of {len(pos)} "
                    f"vertices (expected 0..{len(pos) - 1})")
            chosen = geodesic_region(pos, edge_index, chosen, radius)
    elif vertices:
        raise AttributionArgumentError("vertices", "target 'all' takes no vertices")

    result = attribute(model, pair, frame, target=target, target_vertices=chosen,
                       output=output, reduction=reduction, n_steps=n_steps)
    values = result.heat(heat)
    marked = None if target == "all" else result.target_vertices
    title = (f"{output} at vertex {int(result.target_vertices[0])}" if target == "vertex"
             else f"{output}, {target} ({len(result.target_vertices)} vertices)")
    out = Path(out)
    files = {
        "png": render_attribution(out / f"{stem}.png", pos, faces, values, targets=marked,
                                  title=f"{title}\n{heat} channels, max {values.max():.2e}",
                                  scale=scale),
        "ply": write_attribution_ply(out / f"{stem}.ply", pos, faces, values, scale=scale),
        "npz": result.save(out / f"{stem}.npz"),
    }
    summary = result.summary() | {"frame": frame_index, "heat": heat,
                                  "files": {k: str(v) for k, v in files.items()}}
    if target != "all" and values.max() > 0:
        field = influence_field(values, pos, edge_index, result.target_vertices)
        summary["influence_field_90"] = {
            "vertices": field.count, "geodesic_radius_m": field.radius, "hops": field.hops,
            "support": field.support, "support_hops": field.support_hops}
    json_path = out / f"{stem}.json"
    summary["files"]["json"] = str(json_path)
    atomic_write_bytes(json_path, json.dumps(summary, indent=2).encode())
    return summary
