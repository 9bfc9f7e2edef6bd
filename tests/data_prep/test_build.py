"""Dataset build: a build killed with SIGKILL resumes without re-simulating finished
sequences and never reads a partial file; sequences that failed their gates are not
simulated again with the same inputs; config values are checked before any work."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import pytest
from omegaconf import OmegaConf

from data_prep.build import build_dataset
from data_prep.config import DataConfig
from data_prep.plan import plan_dataset
from gnngarment.config import load_config
from gnngarment.data import PreparedDataset
from gnngarment.data.cache import read_garment, read_sequence, write_garment
from gnngarment.io.atomic import TEMP_SUFFIX
from gnngarment.paths import REPOSITORY_ROOT

TINY = REPOSITORY_ROOT / "configs" / "data" / "tiny.yaml"


def tiny_config(output: Path) -> DataConfig:
    config = load_config(TINY, DataConfig)
    config.output = str(output)
    config.simulation = str(REPOSITORY_ROOT / config.simulation)
    return config


def _children(pid: int) -> list[int]:
    """Processes whose parent is ``pid`` (Linux ``/proc``)."""
    found = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        found += [int(child) for child in (task / "children").read_text().split()]
    return found


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, reaped by init later, has stopped)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.slow
def test_build_killed_mid_way_resumes(tmp_path: Path) -> None:
    """Start `gnngarment prepare` with one worker, SIGKILL the builder as soon as the
    first sequence is written: its worker stops with it (it does not go on writing into
    the cache). Rebuild: finished sequences are skipped, the rest are simulated, and
    every sequence in the manifest reads back complete."""
    config = tiny_config(tmp_path / "data")
    config_file = tmp_path / "tiny.yaml"
    config_file.write_text(OmegaConf.to_yaml(OmegaConf.create(asdict(config))))
    process = subprocess.Popen(
        [sys.executable, "-m", "gnngarment.cli", "prepare", "--config", str(config_file),
         "--workers", "1"], cwd=REPOSITORY_ROOT, stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL, start_new_session=True)
    sequences = tmp_path / "data" / "sequences"
    deadline = time.monotonic() + 600
    try:
        while not list(sequences.glob("*.hash")):
            assert process.poll() is None, "the build ended before it could be killed"
            assert time.monotonic() < deadline, "no sequence written in 10 minutes"
            time.sleep(0.05)
        workers = _children(process.pid)
        os.kill(process.pid, signal.SIGKILL)  # the builder alone, as `kill -9` does
        process.wait()
        stopped = time.monotonic() + 5.0
        while any(_alive(pid) for pid in workers) and time.monotonic() < stopped:
            time.sleep(0.05)
        assert workers and not any(_alive(pid) for pid in workers), \
            "a simulation worker outlived its killed build"
    finally:
        os.killpg(process.pid, signal.SIGKILL)  # whatever is left of the process group
        process.wait()
    finished = {p.stem for p in sequences.glob("*.hash")}
    assert not (tmp_path / "data" / "manifest.json").exists()
    planned = {p.name for p in plan_dataset(config)}
    assert finished < planned  # killed part-way

    report = build_dataset(replace(config, workers=1), log=lambda _: None)
    assert report["skipped_existing"] >= len(finished)
    assert report["simulated"] + report["skipped_existing"] == len(planned)
    manifest = json.loads((tmp_path / "data" / "manifest.json").read_text())
    built = set(manifest["sequences"])
    assert finished <= built
    assert built | set(report["failed_sequences"]) == planned
    for split in ("train", "val", "test"):
        dataset = PreparedDataset(tmp_path / "data", split, window=3)
        for name in dataset.sequence_names:
            batch = dataset.batch([(name, [0, dataset.frame_counts[name] - 1])])
            assert batch.target.isfinite().all()
    # Every sequence starts from its garment's template, the drape on the still rest
    # body: frame 0 is the template, and the motion's rest hold (all frames here) keeps
    # the garment within a few mm of it (DESIGN.md: the template is the garment as worn).
    moved = []
    for name, info in manifest["sequences"].items():
        garment = read_garment(tmp_path / "data", info["garment"])
        positions = read_sequence(tmp_path / "data", name).positions
        assert np.abs(positions[0] - garment.rest_pos).max() < 1e-5, name
        drift = np.linalg.norm(positions - garment.rest_pos, axis=2).mean(axis=1).max()
        assert drift < 0.015, (name, drift)  # tiny drapes stop at 30 frames: 3-9 mm
        moved.append(np.linalg.norm(garment.rest_pos - garment.design_pos, axis=1).mean())
    assert max(moved) > 0.002  # the templates are drapes, not the designs
    # The killed build's temporary files (if it died mid-write) were cleaned up.
    assert not [p for p in (tmp_path / "data").rglob(f"*{TEMP_SUFFIX}")]

    again = build_dataset(replace(config, workers=1), log=lambda _: None)
    assert again["simulated"] == 0  # built and failed sequences are both remembered
    assert again["manifest_hash"] == report["manifest_hash"]

    # A garment written by an older builder (cache format 2: no joint distances) is
    # completed on resume, to the numbers a fresh drape writes, and nothing is simulated.
    name = next(iter(manifest["sequences"].values()))["garment"]
    fresh = read_garment(tmp_path / "data", name)
    write_garment(tmp_path / "data", replace(fresh, joint_distances=None))
    lines: list[str] = []
    upgraded = build_dataset(replace(config, workers=1), log=lines.append)
    assert upgraded["simulated"] == 0
    assert any("1 garments draped by an older builder completed" in line for line in lines)
    np.testing.assert_allclose(read_garment(tmp_path / "data", name).joint_distances,
                               fresh.joint_distances, atol=1e-6)


@pytest.mark.parametrize(("override", "key"), [
    ({"motions": ["walk", "moonwalk"]}, "motions"),
    ({"garment_types": ["poncho"]}, "garment_types"),
    ({"fps": -30.0}, "fps"),
    ({"garment_vertices": [420, 300]}, "garment_vertices"),
    ({"drape_frames": 0}, "drape_frames"),
])
def test_bad_config_values_name_the_file_and_key(tmp_path: Path, override: dict,
                                                  key: str) -> None:
    """An unknown name or a value out of range is a config error before any work (issue
    15: `fps: -30` and unknown motions used to build with every sequence left out)."""
    from gnngarment.config import ConfigError

    values = OmegaConf.merge(OmegaConf.load(TINY), override)
    path = tmp_path / "bad.yaml"
    path.write_text(OmegaConf.to_yaml(values))
    with pytest.raises(ConfigError, match=rf"{path}: key '{key}'"):
        load_config(path, DataConfig)


@pytest.mark.parametrize("worker", ["drape_worker", "sequence_worker"])
def test_the_workers_compute_on_one_thread(monkeypatch, tmp_path: Path, worker: str) -> None:
    """Whatever thread counts the caller set, both build workers run torch and every
    BLAS/OpenMP library on one thread: the cache's bits must not depend on the machine's
    cores (LAPACK's eigenvalues of a benchmark garment's Nyström descriptor differ by up
    to 9.4e-16 between one and two threads)."""
    import importlib

    import torch
    from threadpoolctl import threadpool_info, threadpool_limits

    module = importlib.import_module(f"data_prep.{worker}")
    seen: list[set[int]] = []

    def record(*_: object) -> None:  # the first thing either worker calls
        seen.append({pool["num_threads"] for pool in threadpool_info()}
                    | {torch.get_num_threads()})
        raise RuntimeError("stop here")

    monkeypatch.setattr(module, "anny_body_model", record)
    config = tiny_config(tmp_path / "data")
    plan = plan_dataset(config)[0]
    task = ((str(tmp_path / "data"), plan.design, plan.body, config, "hash")
            if worker == "drape_worker" else (str(tmp_path / "data"), plan, config, "hash"))
    run = (module.drape_and_prepare_garment if worker == "drape_worker"
           else module.simulate_sequence)
    before = torch.get_num_threads()
    with threadpool_limits(limits=2):
        torch.set_num_threads(2)
        try:
            status = run(task)
        finally:
            torch.set_num_threads(before)
    assert seen == [{1}]
    assert "stop here" in str(status)  # reported as crashed, not raised
