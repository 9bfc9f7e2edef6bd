"""The real end-to-end path (what `make demo` runs, on the tiny dataset): Newton
simulation → training through both stages → evaluation → animating an unseen garment →
exports → attribution heatmap."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gnngarment.demo import run
from gnngarment.geometry import load_mesh
from gnngarment.inference.export import read_point_cache
from gnngarment.paths import REPOSITORY_ROOT


@pytest.mark.slow
@pytest.mark.timeout(1500)
def test_quick_demo_end_to_end(tmp_path: Path, anny_body) -> None:
    configs = REPOSITORY_ROOT / "configs"
    summary = run(tmp_path / "out", configs / "data" / "tiny.yaml",
                  configs / "train" / "tiny.yaml", None, attribution_steps=4,
                  motion_seconds=0.3, workspace=tmp_path / "work",
                  unseen_resolution=(400, 600), unseen_drape_frames=30)
    assert summary["dataset"]["splits"]["train"] >= 1
    assert summary["training"]["epochs"] == 3
    assert [s["to"] for s in summary["training"]["switches"]][:2] == ["physics",
                                                                      "physics_strain"]
    assert np.isfinite(summary["evaluation"]["demo run"]["e_verts_mm"])
    files = summary["files"]
    pos, _ = load_mesh(files["garment"])
    assert read_point_cache(files["pc2"]).shape == (summary["animation"]["frames"], len(pos), 3)
    for key in ("glb", "gif", "heatmap", "evaluation"):
        assert Path(files[key]).is_file(), key
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["animation"]["vertices"] \
        == len(pos)
