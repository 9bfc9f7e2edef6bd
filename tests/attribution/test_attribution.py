"""The Attribution result: heat maps, summary, file round trip."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gnngarment.attribution import Attribution


def make(attributions: np.ndarray, value: float = 2.0, baseline: float = 0.5,
         delta: float = 3e-4) -> Attribution:
    return Attribution(attributions=attributions, target="vertex",
                       target_vertices=np.array([1]), output="blend_shapes", reduction="norm",
                       value=value, baseline_value=baseline, delta=delta, n_steps=50,
                       seconds=1.5)


def test_heat_channels() -> None:
    attributions = np.zeros((3, 30), np.float32)
    attributions[0, 3:6] = [1.0, -2.0, 0.5]      # normal channels
    attributions[1, 0] = -4.0                    # position
    attributions[2, 29] = 7.0                    # a joint distance
    result = make(attributions)
    np.testing.assert_allclose(result.heat(), [3.5, 0.0, 0.0])
    np.testing.assert_allclose(result.heat("all"), [3.5, 4.0, 7.0])
    totals = result.channel_totals()
    np.testing.assert_allclose(totals["position"], [0.0, 4.0, 0.0])
    np.testing.assert_allclose(totals["joint_distances"], [0.0, 0.0, 7.0])
    with pytest.raises(ValueError, match="unknown heat channels 'tangent'"):
        result.heat("tangent")


def test_relative_delta_and_summary() -> None:
    result = make(np.ones((2, 30)))
    assert result.relative_delta == pytest.approx(2e-4)
    assert make(np.zeros((2, 30)), 1.0, 1.0, 0.0).relative_delta == 0.0
    summary = json.loads(json.dumps(result.summary()))
    assert summary["sum_of_attributions"] == 60.0
    assert summary["abs_share"]["joint_distances"] == pytest.approx(0.8)


def test_save_and_load(tmp_path) -> None:
    result = make(np.random.default_rng(0).normal(size=(4, 30)).astype(np.float32))
    path = result.save(tmp_path / "a.npz")
    loaded = Attribution.load(path)
    np.testing.assert_array_equal(loaded.attributions, result.attributions)
    assert (loaded.target, loaded.output, loaded.n_steps) == ("vertex", "blend_shapes", 50)
    assert loaded.delta == result.delta and loaded.target_vertices.tolist() == [1]
    with pytest.raises(ValueError, match="file not found"):
        Attribution.load(tmp_path / "missing.npz")
