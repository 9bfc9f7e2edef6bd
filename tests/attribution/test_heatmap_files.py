"""``run_attribution``: the heatmap files of one attribution, and its input errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gnngarment.attribution import Attribution
from gnngarment.attribution.heatmap_files import run_attribution
from gnngarment.data.body_inputs import BodyMotionInputs, BodyShapeInputs
from tests.attribution.conftest import build


def body_inputs(body_vertices: int, frames: int = 4) -> tuple[BodyShapeInputs, BodyMotionInputs]:
    rng = np.random.default_rng(2)
    skin_rng = np.random.default_rng(3)  # its own stream: the motion stays as it was
    shape = BodyShapeInputs(joints=rng.normal(scale=0.3, size=(24, 3)).astype(np.float32),
                            distances=rng.random((body_vertices, 24)).astype(np.float32),
                            subset=np.arange(body_vertices),
                            rest_vertices=skin_rng.normal(scale=0.3, size=(40, 3)),
                            faces=np.zeros((0, 3), np.int64),
                            skinning_weights=skin_rng.dirichlet(np.ones(24), size=40))
    motion = BodyMotionInputs(
        motion_features=(rng.normal(size=(frames, 75)) * 0.2).astype(np.float32),
        velocities=(rng.normal(size=(frames, body_vertices, 3)) * 0.1).astype(np.float32),
        joint_transforms=np.tile(np.eye(4, dtype=np.float32), (frames, 24, 1, 1)),
        vertices=np.zeros((frames, 40, 3), np.float32), fps=30.0)
    return shape, motion


def test_writes_png_ply_npz_json(tmp_path, garment) -> None:
    model = build(levels=2)
    shape, motion = body_inputs(model.config.body_vertices)
    summary = run_attribution(model, *garment, shape, motion, tmp_path, n_steps=4,
                              scale="log")
    files = {key: tmp_path / f"attribution.{key}" for key in ("png", "ply", "npz", "json")}
    assert all(path.is_file() for path in files.values())
    assert summary["frame"] == 2 and summary["target"] == "vertex"
    assert json.loads(files["json"].read_text())["delta"] == summary["delta"]
    result = Attribution.load(files["npz"])
    assert result.attributions.shape == (144, 30) and result.n_steps == 4
    assert summary["influence_field_90"]["support"] > 0


def test_region_by_radius_and_all(tmp_path, garment) -> None:
    model = build(levels=0)
    shape, motion = body_inputs(model.config.body_vertices)
    region = run_attribution(model, *garment, shape, motion, tmp_path, target="region",
                             vertices=[75], radius=0.05, n_steps=2, stem="region")
    # 3.5 cm between rings, 23 cm around: the rings above and below, not the neighbours.
    assert region["target_vertices"] == [67, 75, 83]
    everything = run_attribution(model, *garment, shape, motion, tmp_path, target="all",
                                 output="posed", n_steps=2, stem="all", frame_index=0)
    assert everything["frame"] == 0 and "influence_field_90" not in everything


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"target": "edge"}, "unknown target kind 'edge'"),
    ({"heat": "tangent"}, "unknown heat channels"),
    ({"scale": "cubic"}, "unknown colour scale"),
    ({"vertices": [999]}, "target vertex 999 is out of range"),
    ({"target": "region"}, "target 'region' needs vertices"),
    ({"target": "region", "vertices": [999], "radius": 0.1}, "region centre out of range"),
    ({"frame_index": 4}, "frame index 4 is out of range"),
])
def test_bad_options(tmp_path, garment, kwargs, message) -> None:
    model = build(levels=0)
    shape, motion = body_inputs(model.config.body_vertices)
    with pytest.raises(ValueError, match=message):
        run_attribution(model, *garment, shape, motion, tmp_path, n_steps=2, **kwargs)
    assert list(tmp_path.iterdir()) == []
