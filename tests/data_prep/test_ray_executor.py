"""`prepare --executor ray`: Ray tasks on a local Ray instance (2 CPUs, this machine only)
build the tiny config with the same manifest (byte-identical cache files) as the local
process pool; a Ray worker SIGKILLed mid-build is retried and nothing is lost or left
half-written; the executor and config keys are validated; a missing Ray is one line."""

from __future__ import annotations

import hashlib
import importlib.util
import itertools
import json
import os
import signal
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from data_prep.build import build_dataset
from data_prep.build_records import _intact_npz, lost_task
from data_prep.config import DataConfig
from data_prep.plan import plan_dataset
from gnngarment.cli import app
from gnngarment.config import ConfigError, merge_config
from gnngarment.io.atomic import TEMP_SUFFIX
from tests.data_prep.test_build import tiny_config

HAVE_RAY = importlib.util.find_spec("ray") is not None
needs_ray = pytest.mark.skipif(not HAVE_RAY, reason="Ray is not installed: "
                               "pip install -e '.[ray]' (make test installs it)")


# ----------------------------------------------------------- worker functions (tests)
#: Ray's system setting for its workers' nice value (its own spelling).
RAY_NICENESS = "RAY_worker_niceness"


@pytest.fixture(autouse=True, scope="module")
def _workers_at_normal_priority():
    """Ray runs its workers at nice 15; beside any busy process at nice 0 (the other
    test worker, a build in the background) they get a few % of a core, and a 20 s
    test took 7 min (measured). The Ray instances these tests start run them at the
    priority of the local process pool they are compared with."""
    previous = os.environ.get(RAY_NICENESS)
    os.environ[RAY_NICENESS] = "0"
    yield
    if previous is None:
        os.environ.pop(RAY_NICENESS, None)
    else:
        os.environ[RAY_NICENESS] = previous


# Module-level, so that Ray workers import them by name (the repository root is the
# driver's working directory, which Ray puts on the workers' path).
def timed_sleep(seconds: float) -> tuple[float, float, int]:
    """Sleep; return (start, end) wall-clock times [s] and the worker's pid."""
    start = time.time()
    time.sleep(seconds)
    return start, time.time(), os.getpid()


def die(_: object) -> None:
    """Kill the worker process running this task."""
    os.kill(os.getpid(), signal.SIGKILL)


# ------------------------------------------------------------------------- helpers
#: A MAT-file starts with a 116-byte text header that holds the time it was written
#: ("MATLAB 5.0 MAT-file ... Created on: ..."); the rest is its data.
MAT_HEADER = 116


def raw_contents(root: Path) -> dict[str, str]:
    """sha256 of every raw (CLOTH3D-layout) file, without a ``.mat`` file's header."""
    return {str(p.relative_to(root)):
            hashlib.sha256(p.read_bytes()[MAT_HEADER if p.suffix == ".mat" else 0:]).hexdigest()
            for p in sorted((root / "raw").rglob("*")) if p.is_file()}


def same_build(root: Path, reference: Path) -> None:
    """The manifests agree (splits, sequences, the sha256 of every cache file and so the
    manifest hash): the cache files are byte-identical; so are the raw files but for the
    write time in a ``.mat`` header. No temporary or truncated file is left."""
    manifest = json.loads((root / "manifest.json").read_text())
    expected = json.loads((reference / "manifest.json").read_text())
    for key in ("splits", "sequences", "files", "sizes", "hash", "builder_version",
                "format_version"):
        assert manifest[key] == expected[key], key
    assert raw_contents(root) == raw_contents(reference)
    assert not list(root.rglob(f"*{TEMP_SUFFIX}")), "a temporary file was left behind"
    for name in manifest["files"]:
        assert _intact_npz(root / name), name


@pytest.fixture(scope="module")
def local_build(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tiny config built by the local process pool (2 workers)."""
    root = tmp_path_factory.mktemp("local") / "data"
    build_dataset(replace(tiny_config(root), workers=2), log=lambda _: None)
    return root


@pytest.fixture(scope="module")
def ray_session():
    """A Ray instance of 2 CPUs on this machine. Nothing connects off the machine; Ray
    2.60 listens on the node's own address (it replaces 127.0.0.1 by it), with its
    token authentication on."""
    import ray

    ray.init(address="local", num_cpus=2, include_dashboard=False,
             object_store_memory=100 * 1024 * 1024, log_to_driver=False)
    yield ray
    ray.shutdown()


# ---------------------------------------------------------------------- executor
@needs_ray
def test_ray_executor_yields_every_result_within_its_in_flight_cap(ray_session) -> None:
    from data_prep.ray_executor import RayExecutor

    with RayExecutor(max_in_flight=1) as executor:
        assert not executor._owned  # the caller's Ray: not shut down on close
        runs = sorted(executor.imap_unordered(timed_sleep, [0.2] * 4))
        assert executor.parallelism(10) == 1
    assert len(runs) == 4
    for (_, end, _), (start, _, _) in itertools.pairwise(runs):
        assert start >= end - 0.01  # one at a time
    assert ray_session.is_initialized()
    with RayExecutor() as executor:
        assert executor.parallelism(10) == 2  # the cluster's CPUs
        pids = {pid for _, _, pid in executor.imap_unordered(timed_sleep, [0.05] * 8)}
    assert len(pids) <= 2  # worker processes are reused across tasks


@needs_ray
def test_a_task_whose_worker_always_dies_is_reported_lost(ray_session) -> None:
    from data_prep.ray_executor import RayExecutor

    with RayExecutor(max_retries=1) as executor:
        results = list(executor.imap_unordered(
            die, ["task"], lost=lambda task, error: (task, type(error).__name__)))
        assert results == [("task", "WorkerCrashedError")]
        with pytest.raises(ray_session.exceptions.WorkerCrashedError):
            list(executor.imap_unordered(die, ["task"]))


@needs_ray
def test_an_executor_that_started_ray_stops_it() -> None:
    """`prepare --executor ray` without a cluster: the executor starts a Ray instance on
    this machine and stops it when closed (in a child process: this one runs Ray)."""
    import subprocess

    code = ("import ray\n"
            "from data_prep.inputs_hash import _hash\n"
            "from data_prep.ray_executor import RayExecutor\n"
            "with RayExecutor() as executor:\n"
            "    assert executor._owned and ray.is_initialized()\n"
            "    assert sorted(executor.imap_unordered(_hash, [1, 2])) == sorted(\n"
            "        [_hash(1), _hash(2)])\n"
            "assert not ray.is_initialized()\n"
            "print('ok')\n")
    from gnngarment.paths import REPOSITORY_ROOT

    done = subprocess.run([sys.executable, "-c", code], cwd=REPOSITORY_ROOT, timeout=300,
                          capture_output=True, text=True,
                          env={**os.environ, "RAY_ADDRESS": "local"})  # not this one's
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-2000:]


def test_a_lost_task_is_named_and_not_recorded_as_failed(tmp_path: Path) -> None:
    """A task whose worker always died is left out under its sequence's (garment's) name
    but leaves no ``.failed`` record: the next build tries it again."""
    plan = plan_dataset(tiny_config(tmp_path))[0]
    error = RuntimeError("worker died")
    sequence = lost_task((str(tmp_path), plan, None, "hash"), error)
    garment = lost_task((str(tmp_path), plan.design, plan.body, None, "hash"), error)
    assert (sequence["name"], garment["name"]) == (plan.name, plan.garment)
    assert not sequence["ok"] and "worker lost" in sequence["reason"]
    assert not list(tmp_path.rglob("*.failed"))


# -------------------------------------------------------------------------- builds
def kill_first_worker_running(task_name: str, killed: list[int], stop: threading.Event,
                              timeout: float = 600.0) -> None:
    """SIGKILL the first process whose title is ``ray::<task_name>`` (a Ray worker
    running that task); append its pid to ``killed``."""
    title = f"ray::{task_name}".encode()
    deadline = time.monotonic() + timeout
    while not stop.is_set() and time.monotonic() < deadline:
        for entry in Path("/proc").iterdir():
            if not entry.name.isdigit():
                continue
            try:
                if (entry / "cmdline").read_bytes().startswith(title):
                    os.kill(int(entry.name), signal.SIGKILL)
                    killed.append(int(entry.name))
                    return
            except OSError:  # the process ended while we looked
                continue
        time.sleep(0.02)


@needs_ray
@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_ray_build_with_a_worker_killed_gives_the_local_manifest(ray_session, local_build: Path,
                                                  tmp_path: Path) -> None:
    """Same plan, same worker functions, same files: a Ray build gives the local process
    pool's manifest (every cache file byte-identical) even when the Ray worker
    simulating the first sequence is SIGKILLed (Ray retries the task), with every planned
    sequence and no temporary or truncated file. (One build checks both: a second tiny
    build just for the unkilled case cost ~40 s of the suite.)"""
    root = tmp_path / "data"
    config = replace(tiny_config(root), executor="ray")
    killed: list[int] = []
    stop = threading.Event()
    killer = threading.Thread(target=kill_first_worker_running,
                              args=("simulate_sequence", killed, stop), daemon=True)
    killer.start()
    try:
        report = build_dataset(config, log=lambda _: None)
    finally:
        stop.set()
        killer.join()
    assert killed, "no Ray worker was seen simulating"
    assert not any("worker lost" in reason for reason in report["failed_sequences"].values())
    planned = {p.name for p in plan_dataset(config)}
    built = set(json.loads((root / "manifest.json").read_text())["sequences"])
    assert built | set(report["failed_sequences"]) == planned
    expected = json.loads((local_build / "build_report.json").read_text())
    assert report["splits"] == expected["splits"]
    assert report["failed_sequences"] == expected["failed_sequences"]
    assert report["failed_garments"] == expected["failed_garments"]
    same_build(root, local_build)
    # The executor is not an input: a local rerun of the Ray build simulates nothing.
    again = build_dataset(replace(config, executor="local", workers=1), log=lambda _: None)
    assert again["simulated"] == 0
    assert again["manifest_hash"] == report["manifest_hash"]


# ------------------------------------------------------------- config and the CLI
@pytest.mark.parametrize(("override", "key"), [
    ({"executor": "dask"}, "executor"),
    ({"ray_address": "auto"}, "ray_address"),  # an address without executor: ray
])
def test_bad_executor_settings_name_the_key(override: dict, key: str) -> None:
    with pytest.raises(ConfigError, match=f"key '{key}'"):
        merge_config(DataConfig, override)


def test_missing_ray_is_one_line_and_exit_2(tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    from omegaconf import OmegaConf

    from gnngarment.paths import REPOSITORY_ROOT

    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` raises ImportError
    config = tmp_path / "tiny.yaml"
    values = OmegaConf.load(REPOSITORY_ROOT / "configs" / "data" / "tiny.yaml")
    config.write_text(OmegaConf.to_yaml(values))
    result = CliRunner().invoke(app, ["prepare", "--config", str(config), "--executor", "ray",
                                      "--output", str(tmp_path / "data")])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert "--executor ray needs Ray" in text and "pip install -e '.[ray]'" in text
    assert "Traceback" not in result.output
    assert not (tmp_path / "data").exists()  # before any work
    result = CliRunner().invoke(app, ["prepare", "--config", str(config), "--executor", "dask"])
    assert result.exit_code == 2 and "key 'executor'" in " ".join(result.output.split())
