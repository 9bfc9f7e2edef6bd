"""CSR sparse matrices of a fixed pattern and their products with dense matrices.

A :class:`CsrPattern` holds the sparsity pattern of a matrix whose values change from
call to call (the attention coefficients of a GAT layer); :class:`CsrMatmul` multiplies
it with a dense matrix, differentiably w.r.t. both the values and the dense operand; a
:class:`SparseOperator` is a constant sparse matrix applied the same way (an unpooling
operator). Patterns keep int32 indices when they fit, MKL's native index type.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import torch

#: Largest int32 value: index arrays with at most this many entries are stored as int32.
INT32_MAX = 2**31 - 1


@contextmanager
def structure_mode() -> Iterator[None]:
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
class CsrPattern:
    """Sparsity pattern of one attention matrix; values are supplied per call.

    Shapes:
        crow ``(R + 1,)``, col ``(nnz,)`` (int32 when it fits: MKL's native index type,
        int64 would be converted on every product).
    """

    crow: torch.Tensor
    col: torch.Tensor
    shape: tuple[int, int]
    #: ``((pattern, copies), ...)`` when this pattern is the block diagonal of ``copies``
    #: copies of each ``pattern`` in turn: its transpose is then assembled from theirs
    #: (built once per pattern) instead of sorted afresh.
    blocks: tuple[tuple[CsrPattern, int], ...] | None = None
    _transpose: tuple[torch.Tensor, torch.Tensor, torch.Tensor] | None = field(
        default=None, repr=False)

    def matrix(self, values: torch.Tensor) -> torch.Tensor:
        return _csr(self.crow, self.col, values, self.shape)

    def transposed(self, values: torch.Tensor) -> torch.Tensor:
        """The transpose with the same values (for the backward pass; built once)."""
        perm, crow_t, col_t = self.transpose_structure()
        # index_select, not values[perm]: advanced indexing was ~3x slower (1.1 vs 0.4 ms
        # for 386k values), once per CSR product in every training step's backward.
        return _csr(crow_t, col_t, values.index_select(0, perm),
                    (self.shape[1], self.shape[0]))

    def transpose_structure(self) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """``(perm, crow_t, col_t)`` of the transpose (built on first use, cached)."""
        if self._transpose is None:
            with structure_mode():
                self._transpose = self._build_transpose()
        return self._transpose

    def _build_transpose(self) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """``(perm, crow_t, col_t)``: the transpose's values are ``values[perm]``."""
        if self.blocks is not None:
            return self._assemble_transpose()
        rows, cols = self.shape
        lengths = (self.crow[1:] - self.crow[:-1]).long()
        row = torch.repeat_interleave(torch.arange(rows, device=self.col.device), lengths)
        col = self.col.long()
        # Values are stored row by row, so a stable sort by column alone gives the
        # (column, row) order; on the int32 columns it was 2.4x faster than sorting an
        # int64 (column, row) key (4.8 vs 11.6 ms for 383k values; training rebuilds it
        # for every batch's new graph).
        perm = torch.argsort(self.col, stable=True)
        counts = torch.bincount(col, minlength=cols)
        crow_t = torch.cat([counts.new_zeros(1), torch.cumsum(counts, 0)])
        return perm, crow_t.to(self.crow.dtype), row[perm].to(self.col.dtype)

    def _assemble_transpose(self) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """The transpose of a block diagonal is the block diagonal of the transposes:
        every block's, offset by the values and rows before it."""
        device = self.col.device
        index_type = self.col.dtype  # offsets added in it: one pass per array
        perms, crows, cols = [], [torch.zeros(1, dtype=self.crow.dtype, device=device)], []
        values = rows = 0
        for pattern, copies in self.blocks or ():
            perm, crow_t, col_t = pattern.transpose_structure()
            nnz = int(pattern.col.shape[0])
            copy = torch.arange(copies, device=device, dtype=index_type)[:, None]
            perms.append((perm[None] + (values + copy.long() * nnz)).flatten())
            crows.append((crow_t.to(self.crow.dtype)[None, 1:] + (values + copy * nnz))
                         .flatten())
            cols.append((col_t.to(index_type)[None] + (rows + copy * pattern.shape[0]))
                        .flatten())
            values += copies * nnz
            rows += copies * pattern.shape[0]
        if values != self.col.shape[0] or rows != self.shape[0]:
            raise ValueError(f"blocks cover {values} values and {rows} rows, the pattern "
                             f"has {self.col.shape[0]} and {self.shape[0]}")
        return torch.cat(perms), torch.cat(crows), torch.cat(cols)


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


class CsrMatmul(torch.autograd.Function):
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
                pattern: CsrPattern) -> torch.Tensor:
        ctx.pattern = pattern
        ctx.save_for_backward(values, dense)
        return _spmm(pattern.matrix(values), dense)

    @staticmethod
    def backward(ctx, grad: torch.Tensor  # type: ignore[override]
                 ) -> tuple[torch.Tensor | None, torch.Tensor | None, None]:
        values, dense = ctx.saved_tensors
        pattern: CsrPattern = ctx.pattern
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
        index_type = torch.int32 if parts[2].numel() <= INT32_MAX else torch.int64
        with structure_mode():
            self.pattern = CsrPattern(parts[0].to(index_type, copy=True),
                                      parts[1].to(index_type, copy=True), tuple(csr.shape))
            self.values = parts[2].clone()

    @property
    def shape(self) -> tuple[int, int]:
        return self.pattern.shape

    def __matmul__(self, dense: torch.Tensor) -> torch.Tensor:
        values = self.values if self.values.dtype == dense.dtype else \
            self.values.to(dense.dtype)
        return CsrMatmul.apply(values, dense, self.pattern)
