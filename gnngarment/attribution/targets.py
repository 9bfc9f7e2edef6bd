"""Choosing what to attribute: a default target vertex and geodesic regions."""

from __future__ import annotations

import numpy as np
import torch

from gnngarment.attribution.errors import AttributionArgumentError
from gnngarment.attribution.frame_inputs import FrameInputs
from gnngarment.data.pair import GarmentBodyPair
from gnngarment.geometry.geodesics import geodesic_distances
from gnngarment.model.deformer import GarmentDeformer


def largest_output_vertex(model: GarmentDeformer, pair: GarmentBodyPair, frame: FrameInputs,
                          output: str = "blend_shapes") -> int:
    """The vertex whose output moves most at ``frame``: ``argmax ‖B_v‖`` (or
    ``‖M_v − T_v‖`` for ``output="posed"``) — where the deformation is, a natural
    default target."""
    was_training = model.training
    model.eval()
    try:
        with torch.no_grad():
            device = next(model.parameters()).device
            frame = frame.to(device)
            context = model.encode([pair])
            out = model(context, frame.motion_window, frame.velocity_window,
                        frame.joint_transforms, frame.dynamic_offsets(model, context))
            values = (out.blend_shapes if output == "blend_shapes"
                      else out.posed - pair.rest_pos.to(device))
    finally:
        model.train(was_training)
    return int(values.norm(dim=-1).argmax())


def geodesic_region(pos: np.ndarray, edge_index: np.ndarray, centres: int | np.ndarray,
                    radius: float) -> np.ndarray:
    """``(K,)`` ascending vertices within geodesic ``radius`` (metres, along edges) of
    any of ``centres`` — a region target around a point of interest.

    Raises:
        ValueError: negative ``radius`` or a centre out of range.
    """
    if not radius >= 0.0:
        raise AttributionArgumentError("radius", f"radius must be >= 0 metres, got {radius}")
    centres = np.atleast_1d(np.asarray(centres, dtype=np.int64))
    distances = geodesic_distances(pos, edge_index, centres).min(axis=0)
    return np.flatnonzero(distances <= radius).astype(np.int64)
