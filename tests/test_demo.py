"""The demo end to end (the README's first command, minus the install)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from gnngarment.demo import run
from gnngarment.geometry import PoolHierarchy, load_mesh


def test_demo_writes_a_garment_a_hierarchy_and_a_summary(tmp_path: Path) -> None:
    summary = run(tmp_path)
    pos, faces = load_mesh(tmp_path / "garment.obj")
    hierarchy = PoolHierarchy.load(tmp_path / "garment.hierarchy.npz")
    assert hierarchy.vertex_counts() == summary["levels"]
    assert hierarchy.num_vertices == len(pos) and summary["components"] == 2
    assert summary["constant_unpool_error"] < 1e-12
    assert json.loads((tmp_path / "summary.json").read_text())["faces"] == len(faces)
    assert np.isfinite(summary["descriptor_head"]).all()
