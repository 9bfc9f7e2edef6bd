"""Loss criteria of the two training stages (blueprint Sec. 3.4, DESIGN.md "Losses"),
one per file, as in HOOD: the training config names the terms of each stage and
:data:`CRITERIA` maps each name to the function that computes it on a batch.

Every term is a pure function of tensors, averaged so that its scale does not depend on
the garment's resolution; the weights (k_v, k_e, ...) live in the training config
(:class:`~gnngarment.training.config.LossWeights`).

Shapes used throughout: ``pred``/``target`` are ``(V, 3)`` vertices (metres) of a batch
of garments, ``edges (2, E)`` and ``faces (F, 3)`` index them.
"""

from __future__ import annotations

from collections.abc import Callable

import torch

from gnngarment.data.dataset import TrainingBatch
from gnngarment.model.deformer import DeformerOutput
from gnngarment.training.criteria import (
    blend_shape,
    collision,
    edge,
    gravity,
    normal,
    strain,
    vertex,
)

#: ``term(output, batch, collision_margin) → scalar``: one unweighted loss term.
Criterion = Callable[[DeformerOutput, TrainingBatch, float], torch.Tensor]

#: Every loss term a stage can name, by the name its weight has in ``LossWeights``.
CRITERIA: dict[str, Criterion] = {
    "vertex": vertex.term,
    "edge": edge.term,
    "normal": normal.term,
    "collision": collision.term,
    "gravity": gravity.term,
    "blend_shape": blend_shape.term,
    "stretch": strain.stretch_term,
    "shear": strain.shear_term,
}
