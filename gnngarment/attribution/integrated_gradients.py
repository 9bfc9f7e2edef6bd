"""Paper Eq. 9: integrated gradients of a garment output with respect to the garment
graph features, by Gauss–Legendre quadrature (captum)."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import torch

from gnngarment.attribution.attribution import OUTPUTS, REDUCTIONS, TARGET_KINDS, Attribution
from gnngarment.attribution.errors import AttributionArgumentError
from gnngarment.attribution.frame_inputs import FrameInputs
from gnngarment.data.pair import GarmentBodyPair
from gnngarment.data.vertex_features import VERTEX_FEATURE_CHANNELS
from gnngarment.model.deformer import GarmentDeformer

#: Vertex rows (quadrature points × garment vertices) evaluated in one forward pass
#: when ``internal_batch_size`` is not given. It bounds memory (configs/model/small.yaml,
#: 2000-vertex skirt: 0.54 GB peak at 1 point per pass, 0.95 GB at 5, 2.4 GB at 25) at
#: no cost in speed: one 2k-vertex garment already saturates a CPU (docs/attribution.md).
DEFAULT_BATCH_VERTICES = 10_000

#: Most quadrature points: Gauss–Legendre with 50 is exact to float32 for this
#: integrand (docs/attribution.md); 1,000 is 20 times the paper's, and time grows with it.
MAX_STEPS = 1000


class FeatureResponse:
    """``f(X)``: a scalar output of the deformer as a function of the graph features.

    Wraps :meth:`GarmentDeformer.encode` + :meth:`GarmentDeformer.forward` for one
    garment–body pair and one frame. Everything but the features (topology, style
    descriptor, body-shape feature, motion) is held fixed. A batch of ``k`` feature
    matrices (captum's scaled inputs) runs as ``k`` copies of the pair in one
    block-diagonal graph, so every copy is independent and one call evaluates ``k``
    quadrature points.

    The scalar is, over the ``K`` target vertices, the mean of each vertex's
    ``‖y_v‖`` (``reduction="norm"``) or ``y_v,x + y_v,y + y_v,z`` (``"sum"``), where
    ``y`` is the blend shape ``B^t`` or the posed displacement ``M^t − T`` (the world
    position minus the rest position, so the target does not depend on where the
    world origin is).

    Args:
        vertices: ``(K,)`` long, the target vertices.
        output: ``"blend_shapes"`` or ``"posed"``; reduction: ``"norm"`` or ``"sum"``.

    Shapes:
        features ``(k, N, 30)`` → ``(k,)``.
    """

    def __init__(self, model: GarmentDeformer, pair: GarmentBodyPair, frame: FrameInputs,
                 vertices: torch.Tensor, output: str = "blend_shapes",
                 reduction: str = "norm"):
        self.model = model
        self.pair = pair
        self.frame = frame
        self.vertices = vertices
        self.output = output
        self.reduction = reduction

    def __call__(self, features: torch.Tensor) -> torch.Tensor:
        copies, n = features.shape[0], features.shape[1]
        pairs = [replace(self.pair, features=features[i]) for i in range(copies)]
        context = self.model.encode(pairs)
        frame = self.frame
        out = self.model(context, frame.motion_window.expand(copies, -1, -1, -1),
                         frame.velocity_window.expand(copies, -1, -1, -1),
                         frame.joint_transforms.expand(copies, -1, -1, -1, -1),
                         frame.dynamic_offsets(self.model, context))
        if self.output == "blend_shapes":
            values = out.blend_shapes.view(copies, n, 3)
        else:
            values = out.posed.view(copies, n, 3) - self.pair.rest_pos
        values = values[:, self.vertices]                                         # (k, K, 3)
        per_vertex = values.norm(dim=-1) if self.reduction == "norm" else values.sum(dim=-1)
        return per_vertex.mean(dim=1)


def attribute(model: GarmentDeformer, pair: GarmentBodyPair,
              frame: FrameInputs | tuple[torch.Tensor, torch.Tensor, torch.Tensor],
              *, target: str = "vertex", target_vertices: int | Sequence[int] | np.ndarray | None
              = None, output: str = "blend_shapes", reduction: str = "norm", n_steps: int = 50,
              internal_batch_size: int | None = None) -> Attribution:
    """Attribute one scalar garment output to the graph features (paper Eq. 9).

    Integrated gradients from the all-zero baseline, ``R = X ⊙ ∫₀¹ ∂f(αX)/∂X dα``,
    with the integral by ``n_steps``-point Gauss–Legendre quadrature (captum's
    ``IntegratedGradients(..., method="gausslegendre")``, exactly Eq. 9). Completeness
    ``ΣR = f(X) − f(0)`` holds up to the quadrature error, reported as ``delta``; the
    model runs in float32, so when ``f(X) − f(0)`` is tiny next to ``f(X)`` itself
    (e.g. ``output="posed"``, dominated by the rigid skinning motion) round-off of
    about ``1e-7 · |f(X)|`` adds to it.

    Args:
        model: the deformer (evaluated in eval mode; its mode is restored afterwards).
        pair: the garment–body pair (:func:`~gnngarment.inference.animate.garment_pair`).
        frame: the frame's inputs (:class:`FrameInputs`, or a ``(motion, velocity,
            transforms)`` tuple shaped ``(1, 1, m, 75)``, ``(1, 1, m, 3 N_b')``,
            ``(1, 1, 24, 4, 4)``, leading axes optional).
        target: ``"vertex"`` (one vertex's output), ``"region"`` (the mean over a set
            of vertices) or ``"all"`` (the mean over the garment).
        target_vertices: the vertex (``"vertex"``) or vertices (``"region"``); must be
            ``None`` for ``"all"``.
        output: ``"blend_shapes"`` (``B^t``) or ``"posed"`` (``M^t − T``).
        reduction: ``"norm"`` or ``"sum"`` of each target vertex's 3-vector.
        n_steps: quadrature points ``N_s`` (the paper uses 50).
        internal_batch_size: quadrature points per forward pass; default: as many as
            keep ``points × N`` under :data:`DEFAULT_BATCH_VERTICES`.

    Returns:
        :class:`Attribution` with ``R (N, 30)``, ``f(X)``, ``f(0)`` and ``delta``.

    Raises:
        ValueError: unknown target kind, output or reduction; a target vertex out of
            range; badly shaped pair or frame inputs (the message names the problem).
    """
    from captum.attr import IntegratedGradients

    n = _check_pair(pair)
    vertices = _target_vertices(target, target_vertices, n)
    if output not in OUTPUTS:
        raise ValueError(f"unknown output '{output}' (expected one of {OUTPUTS})")
    if reduction not in REDUCTIONS:
        raise ValueError(f"unknown reduction '{reduction}' (expected one of {REDUCTIONS})")
    if (isinstance(n_steps, bool) or not isinstance(n_steps, int)
            or not 1 <= n_steps <= MAX_STEPS):
        raise ValueError(f"n_steps must be an integer in 1..{MAX_STEPS}, got {n_steps!r}")
    if internal_batch_size is None:
        internal_batch_size = max(1, min(n_steps, DEFAULT_BATCH_VERTICES // n))
    elif internal_batch_size < 1:
        raise ValueError(f"internal_batch_size must be >= 1, got {internal_batch_size}")
    frame = FrameInputs.coerce(frame, model.config)

    was_training = model.training
    model.eval()
    started = time.perf_counter()
    try:
        # The caller may be inside inference_mode/no_grad (as animate is): IG needs
        # autograd, and tensors made in inference mode cannot enter it, so copy them.
        with torch.inference_mode(False), torch.enable_grad():
            device = next(model.parameters()).device
            pair = _pair_copy(pair, device)
            frame = frame.to(device)
            response = FeatureResponse(model, pair, frame,
                                       torch.as_tensor(vertices, device=device), output,
                                       reduction)
            features = pair.features[None]                                       # (1, N, 30)
            attributions, delta = IntegratedGradients(response).attribute(
                features, baselines=0.0, n_steps=n_steps, method="gausslegendre",
                internal_batch_size=internal_batch_size, return_convergence_delta=True)
            with torch.no_grad():
                value = float(response(features)[0])
                baseline_value = float(response(torch.zeros_like(features))[0])
    finally:
        model.train(was_training)
    return Attribution(
        attributions=attributions[0].detach().cpu().numpy(), target=target,
        target_vertices=vertices, output=output, reduction=reduction, value=value,
        baseline_value=baseline_value, delta=float(delta.reshape(-1)[0]), n_steps=n_steps,
        seconds=time.perf_counter() - started)


def _check_pair(pair: GarmentBodyPair) -> int:
    n = int(pair.rest_pos.shape[0])
    if tuple(pair.features.shape) != (n, VERTEX_FEATURE_CHANNELS):
        raise ValueError(f"pair.features must have shape ({n}, {VERTEX_FEATURE_CHANNELS}) for a "
                         f"{n}-vertex garment, got {tuple(pair.features.shape)}")
    return n


def _target_vertices(target: str, target_vertices: int | Sequence[int] | np.ndarray | None,
                     n: int) -> np.ndarray:
    """``(K,)`` int64 vertex indices of the target, validated against ``n`` vertices."""
    if target not in TARGET_KINDS:
        raise ValueError(f"unknown target kind '{target}' (expected one of {TARGET_KINDS})")
    if target == "all":
        if target_vertices is not None:
            raise AttributionArgumentError(
                "target_vertices", "target 'all' takes no target_vertices (it uses every vertex)")
        return np.arange(n, dtype=np.int64)
    if target_vertices is None:
        raise ValueError(f"target '{target}' needs target_vertices")
    indices = np.atleast_1d(np.asarray(target_vertices))
    if indices.ndim != 1 or indices.size == 0 or not np.issubdtype(indices.dtype, np.integer):
        raise ValueError(f"target_vertices must be integer vertex indices, got "
                         f"{np.asarray(target_vertices)!r}")
    if target == "vertex" and indices.size != 1:
        raise AttributionArgumentError(
            "target_vertices", f"target 'vertex' takes exactly one vertex, got {indices.size} "
            "(use target='region' for several)")
    bad = indices[(indices < 0) | (indices >= n)]
    if bad.size:
        raise AttributionArgumentError(
            "target_vertices", f"target vertex {int(bad[0])} is out of range for a garment "
            f"of {n} vertices (expected 0..{n - 1})")
    if np.unique(indices).size != indices.size:
        raise ValueError("target_vertices contains duplicates")
    return indices.astype(np.int64)


def _pair_copy(pair: GarmentBodyPair, device: torch.device) -> GarmentBodyPair:
    def copy(tensor: torch.Tensor) -> torch.Tensor:
        return tensor.detach().to(device=device, dtype=torch.float32).clone()

    return replace(pair, rest_pos=copy(pair.rest_pos), features=copy(pair.features),
                   descriptor=copy(pair.descriptor), body_distances=copy(pair.body_distances),
                   body_weights=None if pair.body_weights is None else copy(pair.body_weights),
                   joint_distances=(None if pair.joint_distances is None
                                    else copy(pair.joint_distances)))
