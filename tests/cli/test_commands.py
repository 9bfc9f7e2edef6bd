"""The command line as a user runs it: real files, exit codes, no tracebacks."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import trimesh
from typer.testing import CliRunner

from gnngarment.cli import app
from tests.meshes import random_disk, tube, union

runner = CliRunner()


@pytest.fixture(scope="module")
def two_piece(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("garments")
    pos, faces = union(tube(12, 16), random_disk(150, 3))
    mesh = trimesh.Trimesh(pos, faces, process=False)
    paths = {}
    for extension in ("obj", "ply", "glb"):
        paths[extension] = folder / f"two_piece.{extension}"
        mesh.export(paths[extension])
    return paths


@pytest.mark.parametrize("extension", ["obj", "ply", "glb"])
def test_inspect_prints_hierarchy_of_a_two_piece_garment(two_piece, extension: str) -> None:
    result = runner.invoke(app, ["inspect", str(two_piece[extension])])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())  # rich wraps lines at the terminal width
    assert "2 component(s)" in text
    assert "pooling hierarchy" in text and "style descriptor" in text


def test_inspect_json_has_levels_kept_indices_and_descriptor(two_piece) -> None:
    result = runner.invoke(app, ["inspect", str(two_piece["obj"]), "--levels", "3", "--json"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert report["components"] == 2
    assert [level["level"] for level in report["levels"]] == [0, 1, 2, 3]
    assert len(report["levels"][1]["kept"]) == report["levels"][1]["vertices"]
    assert len(report["levels"][0]["centres"]) == 2
    assert len(report["descriptor"]) == 64
    assert set(report["seconds"]) >= {"load", "hierarchy", "descriptor"}


def test_inspect_says_which_attention_path_runs(two_piece, monkeypatch) -> None:
    """The fused operator or the PyTorch fallback, for inference and training, and why a
    fallback is used (issue 39: the user can tell which path ran)."""
    monkeypatch.setenv("GNNGARMENT_ATTENTION", "pytorch")
    result = runner.invoke(app, ["inspect", str(two_piece["obj"]), "--json"])
    assert result.exit_code == 0, result.output
    attention = json.loads(result.output)["attention"]
    assert attention == {"inference": "pytorch", "training": "pytorch",
                         "fallback_reason": "forced by GNNGARMENT_ATTENTION=pytorch"}
    monkeypatch.delenv("GNNGARMENT_ATTENTION")
    attention = json.loads(runner.invoke(app, ["inspect", str(two_piece["obj"]),
                                               "--json"]).output)["attention"]
    assert attention["inference"] in ("fused", "pytorch")
    assert (attention["fallback_reason"] is None) == (attention["inference"] == "fused")


def test_bad_input_exits_2_with_a_message_and_no_traceback(tmp_path: Path) -> None:
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    cases = [
        ([str(tmp_path / "absent.obj")], "absent.obj: file not found"),
        ([str(broken)], "NaN/inf"),
        ([str(broken), "--levels", "-1"], "--levels must be in 0..6"),
        ([str(broken), "--levels", "50"], "--levels must be in 0..6"),  # was quietly capped
    ]
    bad_config = tmp_path / "garment.yaml"
    bad_config.write_text("levles: 2\n")
    cases.append(([str(broken), "--config", str(bad_config)], "levles"))
    for arguments, message in cases:
        result = runner.invoke(app, ["inspect", *arguments])
        assert result.exit_code == 2, result.output
        assert message in " ".join(result.output.split())
        assert "Traceback" not in result.output


def test_evaluate_reports_resolved_and_raw_metrics(tmp_path: Path) -> None:
    import torch

    from gnngarment.model import GarmentDeformer
    from gnngarment.model.checkpoint import model_payload, save_checkpoint
    from tests.model.pairs import tiny_config
    from tests.synthetic_cache import build_synthetic_cache

    cache = build_synthetic_cache(tmp_path / "cache", frames=4)
    torch.manual_seed(0)
    checkpoint = tmp_path / "model.pt"
    save_checkpoint(checkpoint, model_payload(GarmentDeformer(tiny_config())))
    result = runner.invoke(app, ["evaluate", "--checkpoint", str(checkpoint), "--data",
                                 str(cache), "--no-spurious", "--json",
                                 str(tmp_path / "report.json")])
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "report.json").read_text())
    values = report["results"]["ours"]["all"]
    assert {"e_verts_mm", "raw_e_verts_mm", "collision_pct", "raw_collision_pct"} <= set(values)
    # This cache was not built from a synthetic config: no body meshes, nothing resolved.
    assert report["unresolved"] and values["e_verts_mm"] == values["raw_e_verts_mm"]
    assert "Not resolved" in result.output


def test_animate_refuses_a_frame_rate_that_is_not_positive(tmp_path: Path) -> None:
    result = runner.invoke(app, ["animate", str(tmp_path / "any.obj"), "--fps", "0",
                                 "--out", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output  # was animated at 30 fps
    assert "--fps must be a finite number > 0, got 0.0" in " ".join(result.output.split())
    assert not (tmp_path / "out").exists()


@pytest.fixture(scope="module")
def tiny_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from tests.synthetic_cache import build_synthetic_cache

    return build_synthetic_cache(tmp_path_factory.mktemp("cache"), frames=4)


def train_config(folder: Path, cache: Path, **values) -> Path:
    from dataclasses import asdict

    from omegaconf import OmegaConf

    from tests.model.pairs import tiny_config

    path = folder / "train.yaml"
    OmegaConf.save(OmegaConf.create({
        "data": str(cache), "output": str(folder / "run"), "model": asdict(tiny_config()),
        "epochs": 1, "pairs_per_batch": 2, "frames_per_pair": 2, "threads": 1, **values}), path)
    return path


def test_train_refuses_what_it_cannot_do_as_asked(tiny_cache: Path, tmp_path: Path) -> None:
    from gnngarment.model import GarmentDeformer
    from gnngarment.model.checkpoint import model_payload, save_checkpoint
    from tests.model.pairs import tiny_config

    run = tmp_path / "run"
    config = train_config(tmp_path, tiny_cache)
    cases = [
        # No checkpoint to resume: said, not silently started over.
        (["--resume"], "--resume: " + str(run / "last.pt") + ": checkpoint not found"),
        # No epoch would run, so no last.pt would be written.
        (["--set", "epochs=0"], "key 'epochs': must be >= 1, got 0"),
    ]
    for arguments, message in cases:
        result = runner.invoke(app, ["train", "--config", str(config), *arguments])
        assert result.exit_code == 2, result.output
        assert message in " ".join(result.output.split())
        assert not run.exists()
    # A new run into another run's folder: refused before it appends to its metrics.
    save_checkpoint(run / "last.pt", model_payload(GarmentDeformer(tiny_config())))
    (run / "metrics.jsonl").write_text('{"epoch": 1}\n')
    result = runner.invoke(app, ["train", "--config", str(config)])
    assert result.exit_code == 2, result.output
    assert "the output folder holds another run; resume it (--resume)" in " ".join(
        result.output.split())
    assert (run / "metrics.jsonl").read_text() == '{"epoch": 1}\n'
    assert sorted(p.name for p in run.iterdir()) == ["last.pt", "metrics.jsonl"]
    (run / "last.pt").write_bytes(b"not a checkpoint")
    result = runner.invoke(app, ["train", "--config", str(config), "--resume"])
    assert result.exit_code == 2, result.output
    assert "--resume: " in result.output and "not a readable" in result.output
    assert len(result.output.strip().splitlines()) == 1  # torch's message spans many lines


@pytest.mark.parametrize("content", [None, b"not an smpl model"])
def test_prepare_from_cloth3d_with_a_bad_smpl_model_is_one_line_exit_2(
        tmp_path: Path, content: bytes | None) -> None:
    """Issue 13 item 6: a missing or unreadable --smpl-model gave a 55-69-line traceback
    and exit 1; it is checked before any sequence is read."""
    (tmp_path / "cloth3d" / "00001").mkdir(parents=True)
    model = tmp_path / "SMPL_FEMALE.npz"
    if content is not None:
        model.write_bytes(content)
    result = runner.invoke(app, ["prepare", "--from-cloth3d", str(tmp_path / "cloth3d"),
                                 "--smpl-model", str(model), "--output", str(tmp_path / "out")])
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and str(model) in " ".join(result.output.split())
    assert "Traceback" not in result.output and not (tmp_path / "out").exists()


def test_evaluate_refuses_a_mismatched_checkpoint_and_unusable_outputs_up_front(
        tmp_path: Path) -> None:
    """One line, exit 2, before any evaluation: a checkpoint whose weights do not fit its
    model config (a key missing), a --json that is a folder, a --markdown whose folder
    does not exist."""
    import torch

    from gnngarment.model import GarmentDeformer
    from gnngarment.model.checkpoint import model_payload, save_checkpoint
    from tests.model.pairs import tiny_config

    torch.manual_seed(0)
    payload = model_payload(GarmentDeformer(tiny_config()))
    good = tmp_path / "good.pt"
    save_checkpoint(good, payload)
    state = dict(payload["model_state"])
    state.pop(next(iter(state)))
    broken = tmp_path / "broken.pt"
    save_checkpoint(broken, {**payload, "model_state": state})
    cases = [
        (["--checkpoint", str(broken)], "the weights do not fit the model"),
        (["--checkpoint", str(good), "--json", str(tmp_path)], "is a folder"),
        (["--checkpoint", str(good), "--markdown", str(tmp_path / "no" / "t.md")],
         "does not exist"),
    ]
    for arguments, message in cases:
        result = runner.invoke(app, ["evaluate", "--data", str(tmp_path / "none"), *arguments])
        assert result.exit_code == 2, (arguments, result.output)
        text = " ".join(result.output.split())
        assert message in text and "Traceback" not in text, text


def test_a_build_that_loses_every_sequence_exits_non_zero(tmp_path, monkeypatch) -> None:
    """Issue 38: `prepare` whose every sequence failed (motion_seconds: 1e9 hit an
    allocation in each) exited 0 with an empty cache; it now says so and exits 2."""
    import data_prep.build

    def build_nothing(settings, workers=None, log=print):
        return {"output": settings.output, "seconds": 1.0, "planned": 3,
                "splits": {"train": 0, "val": 0, "test": 0},
                "failed_sequences": {"a": "x", "b": "y", "c": "z"},
                "losses_by_reason": {"planned": 3, "lost": 3, "memory": 3}}

    monkeypatch.setattr(data_prep.build, "build_dataset", build_nothing)
    config = tmp_path / "data.yaml"
    config.write_text(f"output: {tmp_path / 'cache'}\n")
    result = runner.invoke(app, ["prepare", "--config", str(config)])
    text = " ".join(result.output.split())
    assert result.exit_code == 2, result.output
    assert "every one of the 3 planned sequences was left out (3 memory;" in text, text
