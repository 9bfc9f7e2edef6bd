"""The blend-shape penalty."""

from __future__ import annotations

import pytest
import torch

from gnngarment.training.criteria.blend_shape import blend_shape_loss


def test_blend_shape_penalty_is_zero_for_plain_skinning_and_only_when_asked() -> None:
    from gnngarment.training.config import LossWeights, StageConfig
    from gnngarment.training.objective import stage_weights

    blend = torch.zeros(5, 3)
    assert float(blend_shape_loss(blend)) == 0.0
    blend[0] = torch.tensor([0.03, 0.0, 0.04])                 # one vertex 5 cm off
    assert float(blend_shape_loss(blend)) == pytest.approx(0.05 ** 2 / 5)
    for stage in ("supervised", "physics", "physics_strain"):
        assert "blend_shape" not in stage_weights(stage, LossWeights(), StageConfig())
        assert stage_weights(stage, LossWeights(blend_shape=100.0),
                             StageConfig())["blend_shape"] == 100.0
