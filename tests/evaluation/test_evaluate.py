from __future__ import annotations

import json
from pathlib import Path

import pytest
import torch

from gnngarment.data import PreparedDataset
from gnngarment.evaluation import evaluate, write_report
from gnngarment.model import GarmentDeformer
from tests.model.pairs import tiny_config
from tests.synthetic_cache import build_synthetic_cache


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_synthetic_cache(tmp_path_factory.mktemp("cache"), frames=5)


def test_report_covers_methods_types_and_metrics(cache: Path, tmp_path: Path) -> None:
    torch.manual_seed(0)
    model = GarmentDeformer(tiny_config())
    dataset = PreparedDataset(cache, "test", model.config.window)
    report = evaluate({"ours": model}, dataset)
    assert set(report.results) == {"ours", "body skinning (LBS)"}
    assert set(report.results["ours"]) == {"tube", "all"}
    values = report.results["ours"]["all"]
    assert values["e_verts_mm"] > 0 and values["spurious_mm"] >= 0
    # The synthetic ground truth is the body-skinned garment lowered by 0.02·speed m.
    lbs = report.results["body skinning (LBS)"]["all"]
    assert lbs["e_verts_mm"] == pytest.approx(1000 * 0.02 * (0.1 + 0.25) / 2, rel=1e-3)
    assert lbs["spurious_mm"] == pytest.approx(0.0, abs=1e-6)  # joint 0 only: no wrist
    write_report(report, tmp_path / "table.md", tmp_path / "report.json")
    table = (tmp_path / "table.md").read_text()
    assert "| ours |" in table and "E_verts" in table
    assert json.loads((tmp_path / "report.json").read_text())["split"] == "test"
