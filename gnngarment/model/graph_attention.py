"""Graph attention (GAT) as edge-wise softmax + one CSR sparse matmul.

:class:`GraphAttention` computes exactly what PyG's ``GATConv`` computes with its default
settings (self loops replaced by one per node, LeakyReLU slope 0.2, bias, a shared
bias-free linear map) and has the same parameters (``lin.weight``, ``att_src``,
``att_dst``, ``bias``), so ``GATConv`` state dicts load into it. It is faster on CPU
because it never gathers an ``(E, heads, channels)`` message tensor: the attention
coefficients become the values of a block-diagonal sparse matrix (one block per head,
interleaved so that node ``i``'s heads are neighbouring rows) and the aggregation is a
single CSR × dense product. With heads averaged (``concat=False``) the average is folded
into the same product: row ``i`` of an ``(N, N·H)`` matrix holds all heads' coefficients.

The index structures (self loops, edges sorted by target, row pointers, per-head column
indices) depend only on the topology, so :class:`AttentionGraph` builds them once and
every layer, frame and call on that graph reuses them.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import torch
from torch import nn
from torch.nn import functional
from torch_geometric.nn.conv import GATConv
from torch_geometric.nn.inits import glorot, zeros

from gnngarment.model.config import ATTENTION_IMPLEMENTATIONS

#: Added to every softmax denominator, as PyG's ``softmax`` does (keeps 0/0 finite).
_SOFTMAX_EPS = 1e-16
_INT32_MAX = 2**31 - 1
#: Largest accepted gap between the cheap softmax shift and the exact segment max. The
#: segment's denominator is then >= exp(-20) = 2e-9 instead of >= 1, so PyG's 1e-16
#: epsilon weighs at most 5e-8 relative (below float32 rounding), and only terms that
#: are < e^-67 of the largest (negligible in any sum) can underflow.
_MAX_SHIFT_GAP = 20.0
#: Logits up to this need no shift at all: exp(60) = 1e26, far from float32's 3e38.
_MAX_UNSHIFTED_LOGIT = 60.0


@contextmanager
def _structure_mode() -> Iterator[None]:
    """Build cached structures as ordinary tensors even inside ``inference_mode``: a
    structure first built during inference is reused by training, and autograd refuses
    to save inference tensors (the gather indices) for the backward pass."""
    with torch.inference_mode(False), torch.no_grad():
        yield


def _csr(crow: torch.Tensor, col: torch.Tensor, values: torch.Tensor,
         shape: tuple[int, int]) -> torch.Tensor:
    # Built from sorted, validated structures: the invariant check would cost a pass.
    # The "CSR is beta" warning is emitted once per process and says nothing actionable.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return torch.sparse_csr_tensor(crow, col, values, size=shape, check_invariants=False)


@dataclass(eq=False)
class _CsrPattern:
    """Sparsity pattern of one attention matrix; values are supplied per call.

    Shapes:
        crow ``(R + 1,)``, col ``(nnz,)`` (int32 when it fits: MKL's native index type,
        int64 would be converted on every product).
    """

    crow: torch.Tensor
    col: torch.Tensor
    shape: tuple[int, int]
    _transpose: tuple[torch.Tensor, torch.Tensor, torch.Tensor] | None = field(
        default=None, repr=False)

    def matrix(self, values: torch.Tensor) -> torch.Tensor:
        return _csr(self.crow, self.col, values, self.shape)

    def transposed(self, values: torch.Tensor) -> torch.Tensor:
        """The transpose with the same values (for the backward pass; built once)."""
        if self._transpose is None:
            with _structure_mode():
                self._transpose = self._build_transpose()
        perm, crow_t, col_t = self._transpose
        return _csr(crow_t, col_t, values[perm], (self.shape[1], self.shape[0]))

    def _build_transpose(self) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """``(perm, crow_t, col_t)``: the transpose's values are ``values[perm]``."""
        rows, cols = self.shape
        lengths = (self.crow[1:] - self.crow[:-1]).long()
        row = torch.repeat_interleave(torch.arange(rows, device=self.col.device), lengths)
        col = self.col.long()
        perm = torch.argsort(col * rows + row, stable=True)
        counts = torch.bincount(col, minlength=cols)
        crow_t = torch.cat([counts.new_zeros(1), torch.cumsum(counts, 0)])
        return perm, crow_t.to(self.crow.dtype), row[perm].to(self.col.dtype)


def _spmm(matrix: torch.Tensor, dense: torch.Tensor) -> torch.Tensor:
    """``matrix @ dense`` for a CSR ``matrix``.

    ``matrix @ dense`` zero-fills a temporary and copies it into the result; ``addmm``
    into an uninitialised output with ``beta=0`` (documented to ignore the output's
    contents, NaN included) skips both and was ~2× faster on this CPU.

    Shapes:
        matrix ``(R, K)`` CSR, dense ``(K, C)`` → ``(R, C)``.
    """
    out = dense.new_empty(matrix.shape[0], dense.shape[1])
    return torch.addmm(out, matrix, dense, beta=0.0, out=out)


class _CsrMatmul(torch.autograd.Function):
    """``matrix(values) @ dense`` differentiable w.r.t. ``values`` and ``dense``.

    torch's own backward through a CSR tensor's values coalesces duplicate entries (a
    multigraph's repeated edges) and then rejects its own gradient's shape; here the
    value gradient is a sampled dense product on the fixed pattern (no dense ``R × K``
    matrix, no ``(nnz, C)`` gather) and the input gradient uses the cached transpose.

    Shapes:
        values ``(nnz,)``, dense ``(K, C)`` → ``(R, C)`` for a pattern of shape ``(R, K)``.
    """

    @staticmethod
    def forward(ctx, values: torch.Tensor, dense: torch.Tensor,  # type: ignore[override]
                pattern: _CsrPattern) -> torch.Tensor:
        ctx.pattern = pattern
        ctx.save_for_backward(values, dense)
        return _spmm(pattern.matrix(values), dense)

    @staticmethod
    def backward(ctx, grad: torch.Tensor  # type: ignore[override]
                 ) -> tuple[torch.Tensor | None, torch.Tensor | None, None]:
        values, dense = ctx.saved_tensors
        pattern: _CsrPattern = ctx.pattern
        grad = grad.contiguous()
        grad_values = grad_dense = None
        if ctx.needs_input_grad[0]:
            # d/dv_p of Σ_rc grad[r,c] (A @ D)[r,c] = <grad[row_p], D[col_p]>.
            grad_values = torch.sparse.sampled_addmm(
                pattern.matrix(values.detach()), grad, dense.detach().t(), beta=0.0).values()
        if ctx.needs_input_grad[1]:
            grad_dense = _spmm(pattern.transposed(values.detach()), grad)
        return grad_values, grad_dense, None


class SparseOperator:
    """A constant sparse matrix applied by CSR products (e.g. an unpooling operator).

    ``torch.sparse.mm`` with a COO matrix zero-fills and copies its output and converts
    indices on every call; this keeps int32 CSR indices, writes the product directly,
    and back-propagates to the dense operand through a transpose built once.

    Shapes:
        matrix ``(R, K)`` sparse (COO or CSR); ``operator @ dense (K, C)`` → ``(R, C)``.
    """

    def __init__(self, matrix: torch.Tensor):
        # Converted under inference_mode (the matrix may be an inference tensor, whose
        # sparse parts cannot be taken outside it), then copied into ordinary tensors.
        with torch.inference_mode():
            csr = matrix.coalesce().to_sparse_csr() if matrix.layout == torch.sparse_coo \
                else matrix.to_sparse_csr()
            parts = (csr.crow_indices(), csr.col_indices(), csr.values())
        index_type = torch.int32 if parts[2].numel() <= _INT32_MAX else torch.int64
        with _structure_mode():
            self.pattern = _CsrPattern(parts[0].to(index_type, copy=True),
                                       parts[1].to(index_type, copy=True), tuple(csr.shape))
            self.values = parts[2].clone()

    @property
    def shape(self) -> tuple[int, int]:
        return self.pattern.shape

    def __matmul__(self, dense: torch.Tensor) -> torch.Tensor:
        values = self.values if self.values.dtype == dense.dtype else \
            self.values.to(dense.dtype)
        return _CsrMatmul.apply(values, dense, self.pattern)


@dataclass(eq=False)
class _HeadLayout:
    """Index structures of an :class:`AttentionGraph` for a given number of heads.

    Attention values are stored target by target, then head by head, then edge by edge
    (``(i, h, k)`` order), so that the values of target ``i`` and head ``h`` are one
    contiguous softmax segment and those of target ``i`` (all heads) one CSR row.

    Attributes:
        source_slot: ``(E'·H,)`` index ``j·H + h`` of each value's source node and head
            into node-major ``(N·H)`` arrays; also the column indices of both matrices.
        target_slot: ``(E'·H,)`` index ``i·H + h`` of each value's softmax segment.
        segment_index: the same as int64 (``scatter_add`` takes no other index type).
        segment_ptr: ``(N·H + 1,)`` int64 offsets of the softmax segments.
        head_rows: ``(N·H, N·H)`` pattern, one row per target and head (concatenated heads).
        node_rows: ``(N, N·H)`` pattern, one row per target (averaged heads).
    """

    source_slot: torch.Tensor
    target_slot: torch.Tensor
    segment_index: torch.Tensor
    segment_ptr: torch.Tensor
    head_rows: _CsrPattern
    node_rows: _CsrPattern


class AttentionGraph:
    """Incoming edges of every node, ready for :class:`GraphAttention`; build once.

    Self loops of the input are dropped and exactly one per node added (``GATConv``'s
    ``add_self_loops=True``), so every node attends at least to itself and no softmax
    segment is empty. Repeated edges are kept, as PyG keeps them.

    Shapes:
        ptr ``(N + 1,)`` int64: incoming edges of node ``i`` are ``ptr[i]:ptr[i+1]``.
        source ``(E',)`` int64: source node of every edge, edges sorted by target.
    """

    def __init__(self, ptr: torch.Tensor, source: torch.Tensor, num_nodes: int):
        self.ptr = ptr
        self.source = source
        self.num_nodes = num_nodes
        self._layouts: dict[int, _HeadLayout] = {}

    @classmethod
    def from_edge_index(cls, edge_index: torch.Tensor, num_nodes: int) -> AttentionGraph:
        """Build from a PyG ``edge_index`` (row 0 sources, row 1 targets).

        Shapes:
            edge_index ``(2, E)`` integer, values in ``[0, num_nodes)``.

        Raises:
            ValueError: bad shape or an index outside ``[0, num_nodes)``.
        """
        if edge_index.dim() != 2 or edge_index.shape[0] != 2:
            raise ValueError(f"edge_index must be (2, E), got {tuple(edge_index.shape)}")
        with _structure_mode():
            return cls._from_edge_index(edge_index.long(), num_nodes)

    @classmethod
    def _from_edge_index(cls, edge_index: torch.Tensor, num_nodes: int) -> AttentionGraph:
        if edge_index.numel() and (int(edge_index.min()) < 0
                                   or int(edge_index.max()) >= num_nodes):
            raise ValueError(f"edge_index has node indices outside [0, {num_nodes})")
        source, target = edge_index
        keep = source != target
        loops = torch.arange(num_nodes, device=edge_index.device)
        source = torch.cat([source[keep], loops])
        target = torch.cat([target[keep], loops])
        # Sorting by (target, source) gives CSR rows; the order inside a row does not
        # change the result beyond float rounding.
        order = torch.argsort(target * max(num_nodes, 1) + source)
        counts = torch.bincount(target, minlength=num_nodes)
        ptr = torch.cat([counts.new_zeros(1), torch.cumsum(counts, 0)])
        return cls(ptr, source[order], num_nodes)

    @property
    def num_edges(self) -> int:
        """``E'``: edges including the self loops."""
        return int(self.source.shape[0])

    @property
    def device(self) -> torch.device:
        return self.source.device

    @property
    def edge_index(self) -> torch.Tensor:
        """``(2, E')`` the edges, self loops included (``GATConv`` accepts it as is: it
        drops and re-adds the self loops)."""
        degree = self.ptr[1:] - self.ptr[:-1]
        target = torch.repeat_interleave(torch.arange(self.num_nodes, device=self.device),
                                         degree)
        return torch.stack([self.source, target])

    def to(self, device: torch.device | str) -> AttentionGraph:
        """This graph on ``device`` (``self`` when already there)."""
        if torch.device(device) == self.device:
            return self
        return AttentionGraph(self.ptr.to(device), self.source.to(device), self.num_nodes)

    def layout(self, heads: int) -> _HeadLayout:
        """Index structures for ``heads`` attention heads (built on first use, cached)."""
        if heads not in self._layouts:
            with _structure_mode():
                self._layouts[heads] = self._build_layout(heads)
        return self._layouts[heads]

    def _build_layout(self, heads: int) -> _HeadLayout:
        n, h_count, device = self.num_nodes, heads, self.device
        degree = self.ptr[1:] - self.ptr[:-1]                                  # (N,)
        target = torch.repeat_interleave(torch.arange(n, device=device), degree)  # (E',)
        local = torch.arange(self.num_edges, device=device) - self.ptr[target]
        head = torch.arange(h_count, device=device)
        # Position of (edge e, head h) in (i, h, k) order.
        position = (self.ptr[target, None] * h_count + head * degree[target, None]
                    + local[:, None]).flatten()
        source_slot = torch.empty_like(position)
        source_slot[position] = (self.source[:, None] * h_count + head).flatten()
        target_slot = torch.empty_like(position)
        target_slot[position] = (target[:, None] * h_count + head).flatten()
        segment_ptr = torch.cat([degree.new_zeros(1),
                                 torch.cumsum(degree.repeat_interleave(h_count), 0)])
        node_ptr = self.ptr * h_count
        index_type = torch.int32 if position.numel() <= _INT32_MAX else torch.int64
        col = source_slot.to(index_type)
        return _HeadLayout(
            # int32 gathers are several times faster than int64 ones on this CPU.
            source_slot=col,
            target_slot=target_slot.to(index_type),
            segment_index=target_slot,
            segment_ptr=segment_ptr,
            head_rows=_CsrPattern(segment_ptr.to(index_type), col, (n * h_count, n * h_count)),
            node_rows=_CsrPattern(node_ptr.to(index_type), col, (n, n * h_count)),
        )


def _softmax_shift(scores: torch.Tensor, heads: int, layout: _HeadLayout,
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


def _segment_sum(values: torch.Tensor, layout: _HeadLayout) -> torch.Tensor:
    """Softmax denominators ``1e-16 + Σ`` over each segment (scatter_add with an int64
    index was ~1.7× faster than ``segment_reduce`` on this CPU).

    Shapes:
        values ``(E'·H,)`` → ``(N·H,)``.
    """
    total = values.new_full((layout.segment_ptr.shape[0] - 1,), _SOFTMAX_EPS)
    return total.scatter_add_(0, layout.segment_index, values)


def _leaky(value: float, negative_slope: float) -> float:
    return value if value >= 0 else negative_slope * value


def _edge_softmax(scores: torch.Tensor, heads: int, layout: _HeadLayout,
                  negative_slope: float) -> torch.Tensor:
    """Attention coefficients ``softmax_k(leaky_relu(a_src[j_k] + a_dst[i]))`` over the
    incoming edges ``k`` of every target ``i``, per head, in the layout's value order.

    As PyG's ``softmax``, ``1e-16`` is added to every denominator (as the sum's initial
    value); the shift subtracted before ``exp`` is :func:`_softmax_shift`'s instead of
    the segment max (the same function; see there).

    Shapes:
        scores ``(N, 3H)`` (see :func:`_softmax_shift`) → ``(E'·H,)``.
    """
    source, target = layout.source_slot, layout.target_slot
    shift = _softmax_shift(scores, heads, layout, negative_slope)
    a_src = scores[:, :heads].reshape(-1)                                      # (N·H,)
    a_dst = scores[:, heads:2 * heads].reshape(-1)
    if torch.is_grad_enabled() and scores.requires_grad:
        logits = functional.leaky_relu(
            a_src.index_select(0, source) + a_dst.index_select(0, target), negative_slope)
        weight = (logits if shift is None else logits - shift.index_select(0, target)).exp()
        total = _segment_sum(weight, layout)
        return weight / total.index_select(0, target)
    # Inference: the same operations in place. Every (E'·H,) temporary is tens of MB,
    # and fresh allocations of that size cost page faults comparable to the arithmetic.
    logits = a_src.index_select(0, source)
    logits += a_dst.index_select(0, target)
    functional.leaky_relu_(logits, negative_slope)
    if shift is not None:
        logits -= shift.index_select(0, target)
    logits.exp_()
    total = _segment_sum(logits, layout)
    logits /= total.index_select(0, target)
    return logits


class GraphAttention(nn.Module):
    """Drop-in replacement of ``GATConv(in_channels, out_channels, heads, concat,
    dropout=dropout)`` (defaults otherwise) computed by a CSR sparse matmul.

    Parameters, their shapes, names and initialisation (glorot, zero bias, drawn in
    ``GATConv``'s order) are ``GATConv``'s, so a seeded construction gives the same
    weights and checkpoints load either way. ``graph`` may be an ``edge_index`` (the
    structure is then built on every call) or an :class:`AttentionGraph` built once.
    Under bf16 autocast the linear map runs in bf16 and the attention in float32 (CPU
    sparse kernels are float32-only, and a bf16 softmax would lose precision).

    Shapes:
        x ``(N, in_channels)``, graph ``(2, E)`` or :class:`AttentionGraph` of ``N`` nodes
        → ``(N, heads · out_channels)`` if ``concat`` else ``(N, out_channels)``.
    """

    def __init__(self, in_channels: int, out_channels: int, heads: int = 1,
                 concat: bool = True, dropout: float = 0.0, negative_slope: float = 0.2):
        super().__init__()
        self.in_channels = in_channels
        self.out_channels = out_channels
        self.heads = heads
        self.concat = concat
        self.dropout = dropout
        self.negative_slope = negative_slope
        self.lin = nn.Linear(in_channels, heads * out_channels, bias=False)
        self.att_src = nn.Parameter(torch.empty(1, heads, out_channels))
        self.att_dst = nn.Parameter(torch.empty(1, heads, out_channels))
        self.bias = nn.Parameter(torch.empty(out_channels * (heads if concat else 1)))
        self.reset_parameters()

    def reset_parameters(self) -> None:
        # GATConv's order (lin, att_src, att_dst, bias): same RNG draws, same weights.
        glorot(self.lin.weight)
        glorot(self.att_src)
        glorot(self.att_dst)
        zeros(self.bias)

    def forward(self, x: torch.Tensor, graph: torch.Tensor | AttentionGraph) -> torch.Tensor:
        if not isinstance(graph, AttentionGraph):
            graph = AttentionGraph.from_edge_index(graph, x.shape[0])
        if graph.num_nodes != x.shape[0]:
            raise ValueError(f"graph has {graph.num_nodes} nodes, x has {x.shape[0]} rows")
        heads, channels = self.heads, self.out_channels
        h = self.lin(x)
        # Both attention scores of every node and head in one small GEMM, (N, 3H), in
        # float32 even under autocast (logit errors are amplified by exp).
        if torch.is_autocast_enabled(h.device.type):
            with torch.autocast(h.device.type, enabled=False):
                h = h.float()
                scores = self._scores(x.float(), h)
        else:
            scores = self._scores(x, h)
        layout = graph.layout(heads)
        alpha = _edge_softmax(scores, heads, layout, self.negative_slope)
        if self.dropout > 0 and self.training:
            alpha = functional.dropout(alpha, self.dropout, training=True)
        dense = h.view(-1, channels)                                          # (N·H, C)
        pattern = layout.head_rows if self.concat else layout.node_rows
        scale = 1.0 if self.concat else 1.0 / heads                            # head mean
        if torch.is_grad_enabled() and (alpha.requires_grad or dense.requires_grad
                                        or self.bias.requires_grad):
            out = _CsrMatmul.apply(alpha, dense, pattern).view(x.shape[0], -1)
            if scale != 1.0:
                out = out.mul_(scale)
            # In place: the product's output is fresh and its backward does not need it.
            return out.add_(self.bias)
        # Inference: one product writes bias + scale · A @ dense into a bias-filled output
        # (saves two passes over the output).
        out = self.bias.to(dense.dtype).repeat(x.shape[0], 1).view(-1, channels)  # a copy
        torch.addmm(out, pattern.matrix(alpha), dense, beta=1.0, alpha=scale, out=out)
        return out.view(x.shape[0], -1)

    def _scores(self, x: torch.Tensor, h: torch.Tensor) -> torch.Tensor:
        """``(N, 3H)``: ``a_src = <h_i,h, att_src_h>``, ``a_dst`` and their sum (the
        self-loop logit before LeakyReLU, for :func:`_softmax_shift`), from whichever of
        ``x`` and ``h = x W^T`` is narrower (a skinny GEMM reading ``(N, 32)`` instead of
        ``(N, 128)`` was ~5× faster; ``x (W^T M) = (x W^T) M`` up to rounding)."""
        matrix = self._score_matrix()
        if self.in_channels < self.heads * self.out_channels:
            return x @ (self.lin.weight.t().to(matrix.dtype) @ matrix)
        return h @ matrix

    def _score_matrix(self) -> torch.Tensor:
        """``(H·C, 3H)`` block matrix: column ``h`` is ``att_src[h]`` on head ``h``'s
        channels, column ``H + h`` is ``att_dst[h]``, column ``2H + h`` their sum."""
        heads, channels = self.heads, self.out_channels
        eye = torch.eye(heads, device=self.att_src.device, dtype=self.att_src.dtype)
        att = torch.cat([self.att_src, self.att_dst, self.att_src + self.att_dst])  # (3,H,C)
        blocks = att[:, :, :, None] * eye[None, :, None, :]                    # (3,H,C,H)
        return blocks.permute(1, 2, 0, 3).reshape(heads * channels, 3 * heads)

    def extra_repr(self) -> str:
        return (f"{self.in_channels}, {self.out_channels}, heads={self.heads}, "
                f"concat={self.concat}")


def graph_attention(in_channels: int, out_channels: int, heads: int, concat: bool,
                    dropout: float = 0.0, attention: str = "csr") -> nn.Module:
    """A GAT layer of the chosen implementation (``"csr"``: :class:`GraphAttention`,
    ``"pyg"``: PyG's ``GATConv``, the reference); both have the same parameters."""
    if attention == "csr":
        return GraphAttention(in_channels, out_channels, heads=heads, concat=concat,
                              dropout=dropout)
    if attention == "pyg":
        return GATConv(in_channels, out_channels, heads=heads, concat=concat, dropout=dropout)
    raise ValueError(f"attention must be one of {ATTENTION_IMPLEMENTATIONS}, got '{attention}'")


def set_attention(module: nn.Module, attention: str) -> nn.Module:
    """Swap every GAT layer inside ``module`` to the ``attention`` implementation in
    place, keeping its weights (the parameters of both have the same names); returns
    ``module``. Used to compare implementations on one trained model."""
    for name, child in list(module.named_children()):
        if isinstance(child, GraphAttention | GATConv):
            in_channels = child.in_channels
            if not isinstance(in_channels, int):
                raise ValueError(f"{name}: bipartite GATConv layers have no CSR counterpart")
            layer = graph_attention(in_channels, child.out_channels, child.heads, child.concat,
                                    child.dropout, attention)
            layer.load_state_dict(child.state_dict())
            layer.to(child.att_src.device)
            layer.train(child.training)
            setattr(module, name, layer)
        else:
            set_attention(child, attention)
    return module


def apply_attention(layer: nn.Module, x: torch.Tensor, edge_index: torch.Tensor,
                    graph: AttentionGraph | Callable[[], AttentionGraph]) -> torch.Tensor:
    """Run a GAT layer of either implementation on one graph.

    PyG's ``GATConv`` gets ``edge_index``; :class:`GraphAttention` gets the prebuilt
    structure (``graph``, or ``graph()`` for a structure that is built lazily, so that
    the PyG path never pays for building it).

    Shapes:
        x ``(N, in)``, edge_index ``(2, E)`` → the layer's output.
    """
    if isinstance(layer, GraphAttention):
        return layer(x, graph if isinstance(graph, AttentionGraph) else graph())
    return layer(x, edge_index)
