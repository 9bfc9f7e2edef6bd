"""Skinning weights from the fused features (blueprint Eq. 6), optionally on a
body-skinning prior."""

from __future__ import annotations

import weakref
from collections import OrderedDict

import torch
from torch import nn

from gnngarment.body.joint_reach import reachable_joints

#: Smallest body weight the prior's logarithm sees: joints the body gives no weight
#: start at ``log(1e-6) ≈ −13.8``, far below, but still reachable by training.
BODY_WEIGHT_FLOOR = 1e-6

#: Reach masks kept between calls, least recently used first out. The mask is a constant
#: of a garment–body pair, but `GarmentDeformer.encode` runs on every training step, and
#: recomputing it cost 5–10 ms per ~900-vertex pair (a few % of a step). A training run
#: sees a few hundred pairs; a mask is ``N × 24`` bools (24 KB at 1,000 vertices).
CACHED_REACH_MASKS = 512
_reach_masks: OrderedDict[tuple[int, int, int, float],
                          tuple[tuple[weakref.ref, ...], torch.Tensor]] = OrderedDict()


def _reachable(rest_pos: torch.Tensor, body_weights: torch.Tensor,
               joint_distances: torch.Tensor, reach: float) -> torch.Tensor:
    """:func:`reachable_joints`, computed once for the same three tensor objects while
    they live (they are a pair's constants: nothing writes them in place)."""
    tensors = (rest_pos, body_weights, joint_distances)
    key = (*(id(t) for t in tensors), reach)
    entry = _reach_masks.get(key)
    if entry is None or any(ref() is not t for ref, t in zip(entry[0], tensors, strict=True)):
        entry = (tuple(weakref.ref(t) for t in tensors),
                 reachable_joints(rest_pos, body_weights, joint_distances, reach))
        _reach_masks[key] = entry
        while len(_reach_masks) > CACHED_REACH_MASKS:
            _reach_masks.popitem(last=False)
    _reach_masks.move_to_end(key)
    return entry[1]


def body_prior_logits(body_weights: torch.Tensor, rest_pos: torch.Tensor | None = None,
                      joint_distances: torch.Tensor | None = None,
                      reach: float | None = None) -> torch.Tensor:
    """``log(max(W_body, 1e-6))``: logits whose softmax is the body weights (up to the
    floor's renormalisation). With ``reach`` (metres), joints out of reach of a vertex on
    the body or on the garment (:func:`~gnngarment.body.joint_reach.reachable_joints`)
    get ``-inf``: no correction the head learns can give them weight, so a trouser leg
    never follows the neck however the motion moves it.

    Shapes: body_weights ``(N, 24)``, rest_pos ``(N, 3)`` and joint_distances ``(N, 24)``
    metres (both needed with ``reach``; ``GarmentBodyPair``) → ``(N, 24)``.
    """
    logits = torch.log(body_weights.clamp_min(BODY_WEIGHT_FLOOR))
    if reach is None:
        return logits
    if rest_pos is None or joint_distances is None:
        raise ValueError("a weight reach needs the garment's rest_pos and joint_distances")
    reachable = _reachable(rest_pos, body_weights, joint_distances, reach)
    return logits.masked_fill(~reachable, -torch.inf)


class SkinningWeightHead(nn.Module):
    """``W = softmax_S(X^fuse · E^t1)`` (Eq. 6), or with ``body_prior``
    ``W = softmax_S(log(max(W_body, 1e-6)) + g · X^fuse · E^t1)``.

    The gate ``g`` is one learnable scalar initialised to 0: the untrained head returns
    the body's skinning weights exactly and training learns a correction. (At ``g = 0``
    the pose code receives no gradient; the gate does, and after the first step so does
    everything before it.) Without the prior the module has no parameters, so state
    dicts saved before the prior existed load unchanged.

    Args:
        body_prior: add the body-skinning prior and its gate.
    """

    def __init__(self, body_prior: bool):
        super().__init__()
        self.body_prior = body_prior
        self.gate = nn.Parameter(torch.zeros(())) if body_prior else None

    def forward(self, fused: torch.Tensor, pose_code: torch.Tensor,
                prior_logits: torch.Tensor | None = None) -> torch.Tensor:
        """Shapes: fused ``(N, S, F)``, pose_code ``(B, F)``, prior_logits ``(N, S)``
        (:func:`body_prior_logits`; required with the prior) → ``(B, N, S)`` weights,
        rows summing to 1."""
        logits = torch.einsum("nsf,bf->bns", fused, pose_code)
        if self.gate is not None:
            if prior_logits is None:
                raise ValueError("the body-skinning prior needs prior_logits (N, S)")
            logits = prior_logits[None] + self.gate * logits
        return torch.softmax(logits, dim=-1)
