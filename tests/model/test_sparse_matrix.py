"""SparseOperator (constant CSR products) against dense matrix products."""

from __future__ import annotations

import torch

from gnngarment.model.sparse_matrix import SparseOperator


def test_sparse_operator_matches_dense_product_and_gradient() -> None:
    generator = torch.Generator().manual_seed(15)
    dense_matrix = torch.rand(30, 20, generator=generator) * (torch.rand(30, 20) < 0.2)
    operator = SparseOperator(dense_matrix.to_sparse())
    x = torch.randn(20, 6, requires_grad=True)
    out = operator @ x
    torch.testing.assert_close(out, dense_matrix @ x)
    weight = torch.randn(30, 6)
    (out * weight).sum().backward()
    torch.testing.assert_close(x.grad, dense_matrix.t() @ weight)
