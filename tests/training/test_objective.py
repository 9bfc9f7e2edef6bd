"""Each stage's loss: which terms it weights (blueprint Sec. 3.4), and their weighted sum."""

from __future__ import annotations

from dataclasses import fields

import pytest
import torch

from gnngarment.training import objective
from gnngarment.training.config import LossWeights, StageConfig
from gnngarment.training.criteria import CRITERIA
from gnngarment.training.objective import loss_terms, stage_loss, stage_weights


def test_each_stage_weights_its_terms() -> None:
    weights, stages = LossWeights(), StageConfig(physics_scale=0.1)
    assert stage_weights("supervised", weights, stages) == {
        "vertex": 100.0, "edge": 15.0, "normal": 50.0}
    physics = stage_weights("physics", weights, stages)
    assert physics == pytest.approx({"vertex": 10.0, "edge": 1.5, "collision": 1.5,
                                     "gravity": 0.1})
    strain = stage_weights("physics_strain", weights, stages)
    assert strain == pytest.approx({**physics, "stretch": 5.0, "shear": 2.0})


def test_supervised_collision_weights_the_collision_term_in_stage_one_only() -> None:
    weights = LossWeights()
    stages = StageConfig(physics_scale=0.1, supervised_collision=100.0)
    assert stage_weights("supervised", weights, stages) == {
        "vertex": 100.0, "edge": 15.0, "normal": 50.0, "collision": 100.0}
    assert stage_weights("physics", weights, stages)["collision"] == pytest.approx(1.5)


def test_every_weighted_term_has_a_criterion() -> None:
    """Each loss weight of the config names a criterion, and an unknown name is refused."""
    assert {f.name for f in fields(LossWeights)} == set(CRITERIA)
    with pytest.raises(ValueError, match="unknown loss term 'bend'"):
        loss_terms(None, None, ["vertex", "bend"], 0.004)


def test_stage_loss_is_the_weighted_sum_of_unweighted_terms(monkeypatch) -> None:
    """Terms are computed once each with the collision margin and summed with the stage's
    weights; the values reported are the unweighted terms."""
    seen = []

    def constant(value):
        def term(output, batch, margin):
            seen.append(margin)
            return torch.tensor(value, requires_grad=True)
        return term

    values = {"vertex": 2.0, "edge": 3.0, "normal": 5.0, "collision": 7.0, "gravity": 11.0,
              "stretch": 13.0, "shear": 17.0, "blend_shape": 19.0}
    monkeypatch.setattr(objective, "CRITERIA", {k: constant(v) for k, v in values.items()})
    weights = LossWeights(blend_shape=1000.0)
    total, reported = stage_loss(None, None, "physics_strain", weights,
                                 StageConfig(physics_scale=0.1), 0.004)
    expected = (10.0 * 2 + 1.5 * 3 + 1.5 * 7 + 0.1 * 11 + 5.0 * 13 + 2.0 * 17 + 1000.0 * 19)
    assert float(total) == pytest.approx(expected)
    assert total.requires_grad
    assert reported == {k: values[k] for k in ("vertex", "edge", "collision", "gravity",
                                                "stretch", "shear", "blend_shape")}
    assert seen == [0.004] * 7
