"""Every speed benchmark in one run; writes ``docs/benchmarks.md``.

1. garment preparation scaling (``prepare_garment.py``: pool hierarchy + Nyström
   descriptor at 1k–50k vertices, growth exponent);
2. inference frames/s of the full model vs the Newton simulator on the same garment,
   and their ratio (``inference_speed.py``);
3. training throughput per stage (``training_speed.py``, on the demo cache);
4. ``gnngarment animate`` end to end (wall clock of the command, from process start to
   the written OBJ/PC2/glb/GIF) on an unseen garment with the shipped model;
5. collision resolution per frame vs the network per frame, and their ratio
   (``collision_resolution_speed.py``).

Each step runs in its own process, one after the other (so they do not share the
cores), and its output goes verbatim into the document under the command that made it.

    .venv/bin/python benchmarks/run_all.py [--quick] [--out docs/benchmarks.md]

``--quick`` cuts the inference benchmark to the small config, the CSR attention, one
thread and no bf16 (about 3 min instead of 25) and preparation to ≤ 20k vertices.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from gnngarment.io.atomic import atomic_write_bytes  # noqa: E402

PYTHON = sys.executable


def run_step(title: str, command: list[str], log: list[str]) -> tuple[int, float]:
    """Run ``command`` from the repository root, echo its output, append a section to
    ``log``; returns (exit code, wall seconds)."""
    shown = " ".join(shlex.quote(".venv/bin/python" if part == PYTHON
                                 else os.path.relpath(part, ROOT)
                                 if part.startswith(str(ROOT) + "/") else part)
                     for part in command)
    print(f"\n=== {title}\n$ {shown}", flush=True)
    load = os.getloadavg()[0]
    tic = time.perf_counter()
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, check=False)
    seconds = time.perf_counter() - tic
    print(done.stdout[-20000:], flush=True)
    if done.returncode != 0:
        print(done.stderr[-5000:], file=sys.stderr, flush=True)
    log.append(f"## {title}\n\n```bash\n{shown}\n```\n\nExit code {done.returncode}, "
               f"{seconds:.0f} s wall, load average {load:.1f} when it started.\n\n"
               f"```text\n{done.stdout.strip()}\n```\n")
    if done.returncode != 0:
        log.append(f"stderr (last lines):\n\n```text\n{done.stderr.strip()[-3000:]}\n```\n")
    return done.returncode, seconds


def unseen_garment_files(folder: Path) -> tuple[Path, Path]:
    """The demo's unseen dress and its body phenotype (a JSON file ``animate`` reads)."""
    from gnngarment.demo import unseen_garment

    path, _, shape = unseen_garment(folder)
    shape_file = folder / "tall.json"
    shape_file.write_text(json.dumps(shape.as_dict()))
    return path, shape_file


def machine() -> str:
    import torch

    from benchmarks.machine import cpu_model

    cpu = cpu_model()
    memory = ""
    try:
        pages = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        memory = f", {pages / 2**30:.0f} GiB"
    except (ValueError, OSError):
        pass
    return (f"{os.cpu_count()} × {cpu}{memory}; Python {platform.python_version()}, "
            f"torch {torch.__version__}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "benchmarks.md")
    parser.add_argument("--data", type=Path, default=ROOT / "data" / "demo",
                        help="prepared cache for the training benchmark")
    args = parser.parse_args()
    started = time.perf_counter()
    log: list[str] = []
    failures = []

    sizes = ["1000", "5000", "20000"] if args.quick else ["1000", "5000", "20000", "50000"]
    code, _ = run_step("1. Garment preparation scaling",
                       [PYTHON, str(ROOT / "benchmarks/prepare_garment.py"), "--sizes", *sizes],
                       log)
    failures += ["preparation"] if code else []

    inference = [PYTHON, str(ROOT / "benchmarks/inference_speed.py")]
    if args.quick:
        inference += ["--configs", "small", "--attention", "csr", "--malloc", "default",
                      "--threads", "1", "--repeats", "3", "--no-bf16"]
    code, _ = run_step("2. Inference vs the Newton simulator", inference, log)
    failures += ["inference"] if code else []

    if (args.data / "manifest.json").is_file():
        code, _ = run_step("3. Training throughput",
                           [PYTHON, str(ROOT / "benchmarks/training_speed.py"),
                            "--data", str(args.data)], log)
        failures += ["training"] if code else []
    else:
        log.append(f"## 3. Training throughput\n\nNot measured: no prepared cache at "
                   f"`{os.path.relpath(args.data, ROOT)}` (run `make demo` or `gnngarment "
                   "prepare --config configs/data/demo.yaml` first).\n")

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        garment, shape = unseen_garment_files(folder)
        code, seconds = run_step(
            "4. `gnngarment animate` end to end (unseen dress, 2 s walk at 30 fps)",
            [PYTHON, "-m", "gnngarment.cli", "animate", str(garment), "--body-shape",
             str(shape), "--motion", "walk", "--duration", "2", "--out",
             str(folder / "animated")], log)
        failures += ["animate"] if code else []
        if code == 0:
            files = [p for p in (folder / "animated").rglob("*") if p.is_file()]
            frames = len(list((folder / "animated").rglob("garment_*.obj")))
            log.append(f"{frames} frames in {seconds:.1f} s including Python start-up, model "
                       f"and Anny loading, context preparation and every export "
                       f"({len(files)} files).\n")

    code, _ = run_step("5. Collision resolution vs the network",
                       [PYTHON, str(ROOT / "benchmarks/collision_resolution_speed.py")], log)
    failures += ["collisions"] if code else []

    total = time.perf_counter() - started
    header = (
        "# Benchmarks\n\n"
        f"Written by `benchmarks/run_all.py{' --quick' if args.quick else ''}` on "
        f"{datetime.date.today().isoformat()} in {total / 60:.1f} min. Machine: {machine()}. "
        "Every number below was printed by the command above it in this one run; the "
        "steps ran one after the other. Interpretation, targets and what was optimised: "
        "[performance.md](performance.md) (inference), [geometry.md](geometry.md) "
        "(preparation), [simulation.md](simulation.md) (the simulator). This page is one "
        "run's snapshot: the current figures are the dated ones at the top of "
        "performance.md, which win where the two differ.\n\n"
        + (f"**Failed steps: {', '.join(failures)}.**\n\n" if failures else ""))
    atomic_write_bytes(args.out, (header + "\n".join(log)).encode())
    print(f"\nwrote {args.out} ({total / 60:.1f} min)")
    raise SystemExit(1 if failures else 0)


if __name__ == "__main__":
    main()
