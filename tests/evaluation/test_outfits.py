"""Layered outfits of a prepared cache: the builder simulates a top over a bottom in one
Newton scene (resumably), and `gnngarment evaluate` reports each garment's E_verts and
the inter-garment penetration of every outfit — a real build-and-evaluate path."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from data_prep.build import build_dataset
from data_prep.config import DataConfig
from data_prep.posed_bodies import synthetic_body_inputs
from gnngarment.config import load_config
from gnngarment.data import CacheError, PreparedDataset
from gnngarment.data.cache import read_garment, read_outfit, read_sequence
from gnngarment.evaluation.outfits import OUTFIT_METRICS, evaluate_outfits, outfit_names
from gnngarment.geometry.garment_layers import LayerSettings, layer_penetration, outward_faces
from gnngarment.model.checkpoint import load_model
from gnngarment.paths import REPOSITORY_ROOT, SHIPPED_MODEL


def outfit_config(output: Path) -> DataConfig:
    """The tiny test build with a bottom and a top held out (trousers and T-shirts in
    turn: the two test designs are trousers002 and tshirt003), at the shipped model's
    levels and body subset so that it can be evaluated on it."""
    config = load_config(REPOSITORY_ROOT / "configs" / "data" / "tiny.yaml", DataConfig)
    return replace(config, output=str(output),
                   simulation=str(REPOSITORY_ROOT / config.simulation),
                   garment_types=["trousers", "tshirt"], body_vertices=128, levels=3,
                   landmarks=64, motion_seconds=0.3, outfits=1, workers=1,
                   splits=replace(config.splits, test_garments=2))


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("outfits") / "data"
    report = build_dataset(outfit_config(root), workers=1)
    assert report["outfits"] == 1, report["failed_outfits"]
    return root


def test_outfit_is_simulated_from_a_layered_start_and_resumed(cache: Path) -> None:
    """The outfit holds both garments on its bottom's sequence: as many frames, starting
    where the top was moved outside the bottom (the drapes, made apart, overlap) and the
    bottom at its template; a second build simulates nothing again."""
    manifest = json.loads((cache / "manifest.json").read_text())
    (name, info), = manifest["outfits"].items()
    assert info["split"] == "test" and f"outfits/{name}.npz" in manifest["files"]
    record = read_outfit(cache, name)
    bottom, top = (read_garment(cache, g) for g in record.garments)
    assert (bottom.garment_type, top.garment_type) == ("trousers", "tshirt")
    sequence = read_sequence(cache, record.sequence)
    for positions, garment in zip(record.positions, (bottom, top), strict=True):
        assert positions.shape == (sequence.num_frames, len(garment.rest_pos), 3)
    for positions, start in zip(record.positions, record.start_pos, strict=True):
        np.testing.assert_allclose(positions[0], start, atol=1e-5)  # frame 0: the start
    np.testing.assert_allclose(record.start_pos[0], bottom.rest_pos, atol=1e-6)
    from data_prep.bodies import anny_body_model, anny_shape
    from data_prep.plan import plan_dataset

    plan = next(p for p in plan_dataset(outfit_config(cache)) if p.name == record.sequence)
    body = anny_body_model().rest(anny_shape(plan.body))
    faces = outward_faces(record.start_pos[0], bottom.faces, body.vertices.numpy(),
                          body.faces)
    # The drapes, made apart, overlap; the outfit's start does not.
    assert layer_penetration(top.rest_pos[None], record.start_pos[0][None], faces,
                             LayerSettings()).max() > 0.0
    assert layer_penetration(record.start_pos[1][None], record.start_pos[0][None], faces,
                             LayerSettings()).max() == 0.0
    again = build_dataset(outfit_config(cache), workers=1)
    assert again["simulated"] == 0 and again["outfits"] == 1


def test_evaluate_reports_every_outfit_per_garment(cache: Path) -> None:
    """Per outfit: finite E_verts of both garments (as an outfit and the top alone),
    penetration shares within [0, 100] with the resolution leaving no more behind than
    the network's output; the CLI prints the outfit table."""
    model = load_model(SHIPPED_MODEL)
    dataset = PreparedDataset(cache, "test", model.config.window)
    names = outfit_names(dataset)
    assert len(names) == 1
    results = evaluate_outfits(model, dataset, synthetic_body_inputs(cache))
    assert set(results) == {*names, "mean"}
    values = results[names[0]]
    assert set(values) == set(OUTFIT_METRICS)
    assert all(np.isfinite(v) for v in values.values())
    assert 0 < values["inner_e_verts_mm"] < 100 and 0 < values["outer_e_verts_mm"] < 100
    assert 0 <= values["through_resolved_pct"] <= values["through_raw_pct"] + 1e-9 <= 100
    done = subprocess.run(
        [sys.executable, "-m", "gnngarment.cli", "evaluate", "--checkpoint", str(SHIPPED_MODEL),
         "--data", str(cache), "--split", "test", "--no-spurious"],
        capture_output=True, text=True, cwd=REPOSITORY_ROOT, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Layered outfits" in done.stdout and names[0][:20] in done.stdout


def test_a_swapped_outfit_file_is_caught_naming_it(cache: Path, tmp_path: Path) -> None:
    """An outfit file replaced after the build (same name, other content) fails the
    manifest's hash check with the file named, before any animation."""
    import shutil

    copy = tmp_path / "data"
    shutil.copytree(cache, copy)
    name = next(iter(json.loads((copy / "manifest.json").read_text())["outfits"]))
    path = copy / "outfits" / f"{name}.npz"
    data = dict(np.load(path))
    data["positions"] = data["positions"] + 0.01
    np.savez(path, **data)
    model = load_model(SHIPPED_MODEL)
    dataset = PreparedDataset(copy, "test", model.config.window)
    with pytest.raises(CacheError, match=name.replace("+", r"\+")):
        evaluate_outfits(model, dataset, synthetic_body_inputs(copy))
