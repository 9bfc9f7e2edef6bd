"""Graph attention (GAT) as edge-wise softmax + one CSR sparse matmul.

:class:`GraphAttention` computes exactly what PyG's ``GATConv`` computes with its default
settings (self loops replaced by one per node, LeakyReLU slope 0.2, bias, a shared
bias-free linear map) and has the same parameters (``lin.weight``, ``att_src``,
``att_dst``, ``bias``), so ``GATConv`` state dicts load into it. It is faster on CPU
because it never gathers an ``(E, heads, channels)`` message tensor: the attention
coefficients (:func:`~gnngarment.model.edge_softmax.edge_softmax`) become the values of
a block-diagonal sparse matrix (one block per head, interleaved so that node ``i``'s
heads are neighbouring rows) and the aggregation is a single CSR × dense product
(:class:`~gnngarment.model.sparse_matrix.CsrMatmul`). With heads averaged
(``concat=False``) the average is folded into the same product: row ``i`` of an
``(N, N·H)`` matrix holds all heads' coefficients. The index structures come from an
:class:`~gnngarment.model.attention_graph.AttentionGraph`, built once per topology.

:func:`graph_attention` builds a GAT layer of either implementation (this one or PyG's
reference), :func:`set_attention` swaps them in a built model and
:func:`apply_attention` runs either on one graph.
"""

from __future__ import annotations

from collections.abc import Callable

import torch
from torch import nn
from torch.nn import functional
from torch_geometric.nn.conv import GATConv
from torch_geometric.nn.inits import glorot, zeros

from gnngarment.model.attention_graph import AttentionGraph
from gnngarment.model.config import ATTENTION_IMPLEMENTATIONS
from gnngarment.model.edge_softmax import edge_softmax
from gnngarment.model.fused_attention import fused_applicable, fused_graph_attention
from gnngarment.model.sparse_matrix import CsrMatmul


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

    def forward(self, x: torch.Tensor, graph: torch.Tensor | AttentionGraph,
                input_columns: torch.Tensor | None = None) -> torch.Tensor:
        """``input_columns`` (``(k,)`` long, optional): ``x`` holds only these columns
        of the layer's input, every other column being zero; the projection then reads
        only the matching columns of ``lin.weight`` (the same result up to rounding, at
        ``k / in_channels`` of the cost). Shapes: ``x (N, k)`` then."""
        if not isinstance(graph, AttentionGraph):
            graph = AttentionGraph.from_edge_index(graph, x.shape[0])
        if graph.num_nodes != x.shape[0]:
            raise ValueError(f"graph has {graph.num_nodes} nodes, x has {x.shape[0]} rows")
        heads, channels = self.heads, self.out_channels
        weight = (self.lin.weight if input_columns is None
                  else self.lin.weight.index_select(1, input_columns))
        h = functional.linear(x, weight)
        # Both attention scores of every node and head in one small GEMM, (N, 3H), in
        # float32 even under autocast (logit errors are amplified by exp).
        if torch.is_autocast_enabled(h.device.type):
            with torch.autocast(h.device.type, enabled=False):
                h = h.float()
                scores = self._scores(x.float(), h, weight.float())
        else:
            scores = self._scores(x, h, weight)
        grad = torch.is_grad_enabled() and (scores.requires_grad or h.requires_grad
                                            or self.bias.requires_grad)
        if fused_applicable(h, self.dropout > 0 and self.training, grad):
            # One pass per CSR row in C++ (gnngarment.model.fused_attention); below is
            # the PyTorch path, the fallback and the reference.
            return fused_graph_attention(h, scores[:, :heads], scores[:, heads:2 * heads],
                                         self.bias, graph, self.negative_slope, self.concat)
        layout = graph.layout(heads)
        alpha = edge_softmax(scores, heads, layout, self.negative_slope,
                             graph.block_layouts(heads))
        if self.dropout > 0 and self.training:
            alpha = functional.dropout(alpha, self.dropout, training=True)
        dense = h.view(-1, channels)                                          # (N·H, C)
        pattern = layout.head_rows if self.concat else layout.node_rows
        scale = 1.0 if self.concat else 1.0 / heads                            # head mean
        if torch.is_grad_enabled() and (alpha.requires_grad or dense.requires_grad
                                        or self.bias.requires_grad):
            out = CsrMatmul.apply(alpha, dense, pattern).view(x.shape[0], -1)
            if scale != 1.0:
                out = out.mul_(scale)
            # In place: the product's output is fresh and its backward does not need it.
            return out.add_(self.bias)
        # Inference: one product writes bias + scale · A @ dense into a bias-filled output
        # (saves two passes over the output).
        rows = x.shape[0] * (heads if self.concat else 1)
        out = torch.empty(rows, channels, dtype=dense.dtype, device=dense.device)
        out.view(x.shape[0], -1).copy_(self.bias.to(dense.dtype).expand(x.shape[0], -1))
        torch.addmm(out, pattern.matrix(alpha), dense, beta=1.0, alpha=scale, out=out)
        return out.view(x.shape[0], -1)

    def _scores(self, x: torch.Tensor, h: torch.Tensor, weight: torch.Tensor) -> torch.Tensor:
        """``(N, 3H)``: ``a_src = <h_i,h, att_src_h>``, ``a_dst`` and their sum (the
        self-loop logit before LeakyReLU, for
        :func:`~gnngarment.model.edge_softmax._softmax_shift`), from whichever of
        ``x`` and ``h = x W^T`` is narrower (a skinny GEMM reading ``(N, 32)`` instead of
        ``(N, 128)`` was ~5× faster; ``x (W^T M) = (x W^T) M`` up to rounding); ``weight``
        is the projection ``h = x weight^T`` used (``lin.weight`` or its input columns)."""
        matrix = self._score_matrix()
        if x.shape[1] < self.heads * self.out_channels:
            return x @ (weight.t().to(matrix.dtype) @ matrix)
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
                    graph: AttentionGraph | Callable[[], AttentionGraph],
                    input_columns: torch.Tensor | None = None) -> torch.Tensor:
    """Run a GAT layer of either implementation on one graph.

    PyG's ``GATConv`` gets ``edge_index``; :class:`GraphAttention` gets the prebuilt
    structure (``graph``, or ``graph()`` for a structure that is built lazily, so that
    the PyG path never pays for building it). ``input_columns``: ``x`` holds only these
    columns of the input, the others are zero (see :meth:`GraphAttention.forward`;
    ``GATConv`` gets the zeros put back).

    Shapes:
        x ``(N, in)`` (``(N, k)`` with ``input_columns``), edge_index ``(2, E)`` → the
        layer's output.
    """
    if isinstance(layer, GraphAttention):
        return layer(x, graph if isinstance(graph, AttentionGraph) else graph(),
                     input_columns)
    if input_columns is not None:
        x = x.new_zeros(x.shape[0], layer.in_channels).index_copy(1, input_columns, x)
    return layer(x, edge_index)
