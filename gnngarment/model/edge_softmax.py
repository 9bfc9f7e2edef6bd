"""Edge softmax: GAT's attention coefficients, normalised over the incoming edges of
every node, per head, as PyG's ``softmax`` computes them (up to rounding), in the value
order of a :class:`~gnngarment.model.attention_graph.HeadLayout`.
"""

from __future__ import annotations

from collections.abc import Sequence

import torch
from torch.nn import functional

from gnngarment.model.attention_graph import HeadLayout

#: Added to every softmax denominator, as PyG's ``softmax`` does (keeps 0/0 finite).
_SOFTMAX_EPS = 1e-16
#: Largest accepted gap between the cheap softmax shift and the exact segment max. The
#: segment's denominator is then >= exp(-20) = 2e-9 instead of >= 1, so PyG's 1e-16
#: epsilon weighs at most 5e-8 relative (below float32 rounding), and only terms that
#: are < e^-67 of the largest (negligible in any sum) can underflow.
_MAX_SHIFT_GAP = 20.0
#: Logits up to this need no shift at all: exp(60) = 1e26, far from float32's 3e38.
_MAX_UNSHIFTED_LOGIT = 60.0


def _softmax_shift(scores: torch.Tensor, heads: int, layout: HeadLayout,
                   negative_slope: float) -> torch.Tensor | None:
    """Per target and head, a constant to subtract from its logits before ``exp``, or
    ``None`` when none is needed.

    Softmax does not depend on it; it only has to keep ``exp`` from overflowing and the
    denominator from becoming so small that underflow or PyG's ``1e-16`` epsilon would
    show. PyG subtracts the segment max, a reduction over all ``E'·H`` logits that cost
    more than the rest of the softmax. Cheaper, from ``N·H`` values only: LeakyReLU is
    increasing, so ``bound_i = leaky(max_j a_src[j] + a_dst[i])`` (max over *all* nodes)
    is ``>=`` every logit into ``i``, and since every node attends to itself the segment
    max is ``>=`` the self-loop logit ``leaky(a_src[i] + a_dst[i])``. Hence

    * every logit ``<= 60`` and every self-loop logit ``>= -20`` (checked from the max
      and min of ``scores``): no shift at all (``exp <= e^60``, denominators
      ``>= e^-20``);
    * else ``bound - self-loop <= _MAX_SHIFT_GAP`` everywhere: subtract the bound;
    * else: subtract the exact segment max, as PyG does.

    Returned detached: it is a constant of the softmax.

    Shapes:
        scores ``(N, 3H)``: ``a_src``, ``a_dst``, ``a_src + a_dst`` → ``(N·H,)`` or ``None``.
    """
    if scores.shape[0] == 0:
        return None
    scores = scores.detach()
    # One pass over all of scores (column-wise reductions of this narrow matrix were ~5×
    # slower): its max bounds both a_src and a_dst, its min bounds a_src + a_dst.
    low, high = (float(v) for v in torch.aminmax(scores))
    if _leaky(2 * high, negative_slope) <= _MAX_UNSHIFTED_LOGIT and \
            _leaky(low, negative_slope) >= -_MAX_SHIFT_GAP:
        return None
    a_src, a_dst = scores[:, :heads], scores[:, heads:2 * heads]
    self_loop = scores[:, 2 * heads:]
    bound = functional.leaky_relu(a_src.max(0).values + a_dst, negative_slope)
    if float((bound - functional.leaky_relu(self_loop, negative_slope)).max()) \
            <= _MAX_SHIFT_GAP:
        return bound.reshape(-1)
    logits = functional.leaky_relu(a_src.reshape(-1).index_select(0, layout.source_slot)
                                   + a_dst.reshape(-1).index_select(0, layout.target_slot),
                                   negative_slope)
    return torch.segment_reduce(logits, "max", offsets=layout.segment_ptr)


def _segment_sum(values: torch.Tensor, layout: HeadLayout) -> torch.Tensor:
    """Softmax denominators ``1e-16 + Σ`` over each segment, for every copy (scatter_add
    with an int64 index was ~1.7× faster than ``segment_reduce`` on this CPU).

    Shapes:
        values ``(copies, E'·H)`` → ``(copies, N·H)`` (``layout`` of one copy).
    """
    copies = values.shape[0]
    total = values.new_full((copies, layout.segment_ptr.shape[0] - 1), _SOFTMAX_EPS)
    return total.scatter_add_(1, layout.segment_index.expand(copies, -1), values)


def _leaky(value: float, negative_slope: float) -> float:
    return value if value >= 0 else negative_slope * value


def edge_softmax(scores: torch.Tensor, heads: int, layout: HeadLayout,
                 negative_slope: float,
                 blocks: Sequence[tuple[HeadLayout, int]] | None = None) -> torch.Tensor:
    """Attention coefficients ``softmax_k(leaky_relu(a_src[j_k] + a_dst[i]))`` over the
    incoming edges ``k`` of every target ``i``, per head, in the layout's value order.

    As PyG's ``softmax``, ``1e-16`` is added to every denominator (as the sum's initial
    value); the shift subtracted before ``exp`` is :func:`_softmax_shift`'s instead of
    the segment max (the same function; see there).

    ``blocks`` describes the graph as runs of identical copies (``(layout of one copy,
    copies)`` in node order, as
    :meth:`~gnngarment.model.attention_graph.AttentionGraph.block_layouts` gives them —
    the frames of one garment). Without autograd, the gathers and sums of every copy
    then use the one copy's index arrays: the same values, but ``copies`` times fewer
    indices read (at 16 frames of a 5,000-vertex garment, 0.5 MB that stays in cache
    instead of 35 MB streamed from memory by every layer). With autograd the flat
    layout is used: the backward of a gather along dim 1 is an ``index_add_`` along
    dim 1, which torch runs index by index on the CPU (measured 1.8× slower steps).

    Shapes:
        scores ``(N, 3H)`` (see :func:`_softmax_shift`) → ``(E'·H,)``.
    """
    shift = _softmax_shift(scores, heads, layout, negative_slope)
    if torch.is_grad_enabled() and scores.requires_grad:
        source, target = layout.source_slot, layout.target_slot
        a_src = scores[:, :heads].reshape(-1)                                  # (N·H,)
        a_dst = scores[:, heads:2 * heads].reshape(-1)
        logits = functional.leaky_relu(
            a_src.index_select(0, source) + a_dst.index_select(0, target), negative_slope)
        weight = (logits if shift is None else logits - shift.index_select(0, target)).exp()
        total = _segment_sum(weight[None], layout)[0]
        return weight / total.index_select(0, target)
    if blocks is None:
        blocks = [(layout, 1)]
    nodes_covered = sum(copies * (base.segment_ptr.shape[0] - 1) // heads
                        for base, copies in blocks)
    values_covered = sum(copies * base.source_slot.shape[0] for base, copies in blocks)
    if nodes_covered != scores.shape[0] or values_covered != layout.source_slot.shape[0]:
        raise ValueError(f"blocks cover {nodes_covered} nodes and {values_covered} values, "
                         f"the graph has {scores.shape[0]} and {layout.source_slot.shape[0]}")
    # Inference: every copy's coefficients computed in place into one output. Every
    # (E'·H,) temporary is tens of MB, and fresh allocations of that size cost page
    # faults comparable to the arithmetic.
    out = scores.new_empty(layout.source_slot.shape[0])
    node = value = 0
    for base, copies in blocks:
        nodes = (base.segment_ptr.shape[0] - 1) // heads
        block = scores[node:node + copies * nodes].view(copies, nodes, 3 * heads)
        a_src = block[:, :, :heads].reshape(copies, nodes * heads)
        a_dst = block[:, :, heads:2 * heads].reshape(copies, nodes * heads)
        source, target = base.source_slot, base.target_slot
        count = copies * source.shape[0]
        logits = out[value:value + count].view(copies, -1)
        torch.index_select(a_src, 1, source, out=logits)
        logits += a_dst.index_select(1, target)
        functional.leaky_relu_(logits, negative_slope)
        if shift is not None:
            block_shift = shift[node * heads:(node + copies * nodes) * heads].view(copies, -1)
            logits -= block_shift.index_select(1, target)
        logits.exp_()
        logits /= _segment_sum(logits, base).index_select(1, target)
        node += copies * nodes
        value += count
    return out
