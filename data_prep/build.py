"""``gnngarment prepare``: build a synthetic CLOTH3D-like dataset and its prepared cache.

Garment designs × bodies × motions are planned deterministically from the config
(:mod:`data_prep.plan`); held-out designs, bodies and motions form the validation and
test splits. Every (design, body) garment is draped on its rest body
(:mod:`data_prep.drape_worker`) and every sequence simulated with Newton
(:mod:`data_prep.sequence_worker`) in worker processes (Warp's CPU kernels use one core
each), checked by the simulator's quality gates, written in the CLOTH3D format under
``raw/`` and as a prepared-cache file under ``sequences/``. A drape or sequence whose
cache file exists with the same inputs hash (:mod:`data_prep.inputs_hash`) is skipped,
so an interrupted build (even kill -9) resumes where it stopped
(:mod:`data_prep.build_records`); files appear only complete (temp + rename);
``manifest.json`` is written last. The workers run in a local process pool or, with
``executor: ray``, as Ray tasks on a cluster (:mod:`data_prep.executor`); the output is
the same either way.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from data_prep.bodies import prepare_body
from data_prep.build_records import (
    garment_done,
    garment_summary,
    known_failure,
    losses_by_reason,
    lost_task,
    sequence_done,
)
from data_prep.config import DataConfig
from data_prep.drape_worker import drape_and_prepare_garment
from data_prep.garment_completion import complete_garment
from data_prep.inputs_hash import (
    BUILDER_VERSION,
    content_inputs,
    garment_inputs_hash,
    outfit_inputs_hash,
    sequence_inputs_hash,
)
from data_prep.outfit_worker import simulate_outfit
from data_prep.plan import BodyPlan, DesignPlan, plan_dataset, plan_outfits
from data_prep.sequence_worker import simulate_sequence
from gnngarment.io.atomic import FolderLock, atomic_write_bytes


def build_dataset(config: DataConfig, workers: int | None = None,
                  log: Callable[[str], None] = print) -> dict[str, Any]:
    """Build (or resume) the dataset of ``config`` under ``config.output``. Validation and
    test sequences are simulated before the training ones.

    Returns:
        The build report (also written to ``build_report.json``).

    Raises:
        FolderBusyError: another build holds ``config.output``.
        RayMissingError: ``config.executor`` is ``ray`` and Ray is not installed.
    """
    if config.executor == "ray":  # before any work, not after the bodies
        from data_prep.ray_executor import import_ray

        import_ray()
    root = Path(config.output)
    with FolderLock(root, "`gnngarment prepare`") as lock:
        # A killed build can leave the temporary file of a write it did not finish: with
        # the lock held no other build is writing here, so those (and only those names)
        # are stale.
        lock.remove_stale_temporaries(CACHE_FOLDERS)
        return _build_locked(root, config, workers, log, lock)


#: The folders a build writes (stale temporary files are looked for only there).
CACHE_FOLDERS = ("raw", "garments", "sequences", "outfits", "topologies", "bodies", ".")


def _build_locked(root: Path, config: DataConfig, workers: int | None,
                  log: Callable[[str], None], lock: FolderLock) -> dict[str, Any]:
    from tqdm import tqdm

    from data_prep.executor import make_executor
    from data_prep.simulate import load_simulation_settings
    from gnngarment.data.cache import write_manifest

    started = time.perf_counter()
    plans = plan_dataset(config)
    settings = load_simulation_settings(config.simulation)
    base_hash = content_inputs(config, settings)

    bodies = {p.body.name: p.body for p in plans}
    for plan in tqdm(bodies.values(), desc="bodies", unit="body"):
        prepare_body(root, plan, config)
    garments: dict[str, tuple[DesignPlan, BodyPlan]] = {}
    for plan in plans:
        garments.setdefault(plan.garment, (plan.design, plan.body))
    drape_tasks, garment_info, failed_garments = [], {}, {}
    completed = 0
    for name, (design, body) in garments.items():
        garment_hash = garment_inputs_hash(base_hash, design, body)
        if garment_done(root, name, garment_hash):
            completed += complete_garment(root, name, body)
            garment_info[name] = garment_summary(root, name)
            continue
        reason = known_failure(root, name, garment_hash, folder="garments")
        if reason is not None:
            failed_garments[name] = reason
            continue
        drape_tasks.append((str(root), design, body, config, garment_hash))

    workers = workers or config.workers or None
    if completed:
        log(f"{completed} garments draped by an older builder completed (joint distances)")
    log(f"{len(garments)} garments planned: {len(garment_info)} already draped, "
        f"{len(failed_garments)} failed before with the same inputs, {len(drape_tasks)} to "
        "drape on their rest bodies")
    results: list[dict[str, Any]] = []
    with make_executor(config.executor, workers, config.ray_address) as executor:
        if executor.describe():
            log(executor.describe())
        if drape_tasks:
            _warm_up_kernels(log)
            for result in tqdm(executor.imap_unordered(drape_and_prepare_garment, drape_tasks,
                                                       lost=lost_task),
                               total=len(drape_tasks), desc="draping", unit="garment"):
                if result["ok"]:
                    garment_info[result["name"]] = result
                else:
                    failed_garments[result["name"]] = result["reason"]
                    log(f"garment {result['name']} left out: {result['reason']}")

        tasks, skipped = [], 0
        known_failures: dict[str, str] = {}
        for plan in plans:
            if plan.garment in failed_garments:
                continue
            inputs_hash = sequence_inputs_hash(base_hash, plan)
            if sequence_done(root, plan.name, inputs_hash):
                skipped += 1
                continue
            reason = known_failure(root, plan.name, inputs_hash)
            if reason is not None:  # same inputs failed before: it would fail again
                known_failures[plan.name] = reason
                continue
            tasks.append((str(root), plan, config, inputs_hash))
        # Held-out sequences first: an interrupted or still-running build can already be
        # evaluated on them (sorted stably, so each group keeps the plan's order).
        tasks.sort(key=lambda task: task[1].split == "train")
        log(f"{len(plans)} sequences planned: {skipped} already built, {len(known_failures)} "
            f"failed before with the same inputs, {len(tasks)} to simulate with "
            f"{executor.parallelism(len(tasks))} worker(s)")
        if tasks:
            if not drape_tasks:
                _warm_up_kernels(log)
            bar = tqdm(executor.imap_unordered(simulate_sequence, tasks, lost=lost_task),
                       total=len(tasks), desc="simulating", unit="sequence")
            for result in bar:
                results.append(result)
                if not result["ok"]:
                    log(f"sequence {result['name']} left out: {result['reason']}")
        failed_outfits: dict[str, str] = {}
        outfits = _build_outfits(root, config, plans, failed_garments, base_hash, executor,
                                 log, failed_outfits)
    # A worker killed mid-write (and retried) left a hidden temporary file; every worker
    # has stopped, so it is stale.
    lock.remove_stale_temporaries(CACHE_FOLDERS)

    failed = known_failures | {r["name"]: r["reason"] for r in results if not r["ok"]}
    built = [p for p in plans if p.garment not in failed_garments and p.name not in failed
             and (root / "sequences" / f"{p.name}.npz").is_file()]
    splits = {split: [p.name for p in built if p.split == split]
              for split in ("train", "val", "test")}
    sequences = {p.name: {"garment": p.garment, "body": p.body.name, "motion": p.motion.name,
                          "frames": round(config.motion_seconds * config.fps),
                          "garment_type": p.design.garment_type, "fabric": p.design.fabric,
                          **({"motion_file": p.motion.file, "subject": p.motion.subject}
                             if p.motion.is_clip else {})}
                 for p in built}
    for plan in built:  # the frame count from the motion actually made
        done = next((r for r in results if r["name"] == plan.name and r["ok"]), None)
        if done is not None:
            sequences[plan.name]["frames"] = done["frames"]
        else:
            from gnngarment.data.cache import read_sequence

            sequences[plan.name]["frames"] = read_sequence(root, plan.name).num_frames
    manifest = write_manifest(root, splits, sequences, extra={
        "builder_version": BUILDER_VERSION, "config": asdict(config),
        "fabric_density": 0.2, "outfits": outfits})
    report = {
        "output": str(root), "seconds": time.perf_counter() - started,
        "planned": len(plans), "skipped_existing": skipped, "simulated": len(results),
        "failed_sequences": failed, "failed_garments": failed_garments,
        "losses_by_reason": losses_by_reason(failed, failed_garments, plans),
        "splits": {k: len(v) for k, v in splits.items()},
        "outfits": len(outfits), "failed_outfits": failed_outfits,
        "seconds_per_frame": float(np.mean([r["seconds_per_frame"] for r in results
                                            if r["ok"]])) if any(r["ok"] for r in results)
        else None,
        "manifest_hash": manifest["hash"], "garments": garment_info,
    }
    atomic_write_bytes(root / "build_report.json", json.dumps(report, indent=2).encode())
    return report


def _build_outfits(root: Path, config: DataConfig, plans: list, failed_garments: dict,
                   base_hash: dict, executor, log: Callable[[str], None],
                   failed: dict[str, str]) -> dict[str, dict[str, Any]]:
    """Simulate the planned layered outfits (:func:`data_prep.plan.plan_outfits`) whose
    garments were draped and whose bottom's sequence was built; return the manifest's
    ``outfits`` (per built outfit: split, sequence, garments innermost first) and put
    in ``failed`` why the others were left out."""
    from tqdm import tqdm

    planned = plan_outfits(config, plans)
    if not planned:
        return {}
    tasks, ready = [], []
    for plan in planned:
        if (any(g in failed_garments for g in plan.garments)
                or not (root / "sequences" / f"{plan.sequence.name}.npz").is_file()):
            failed[plan.name] = "a garment's drape or the bottom's sequence was left out"
            continue
        inputs_hash = outfit_inputs_hash(base_hash, plan)
        reason = known_failure(root, plan.name, inputs_hash, folder="outfits")
        if sequence_done(root, plan.name, inputs_hash, folder="outfits"):
            ready.append(plan)
        elif reason is not None:
            failed[plan.name] = reason
        else:
            tasks.append((str(root), plan, config, inputs_hash))
    log(f"{len(planned)} outfits planned: {len(ready)} already built, {len(tasks)} to "
        "simulate (every garment of one in one scene)")
    built = {plan.name for plan in ready}
    results = executor.imap_unordered(simulate_outfit, tasks, lost=lost_task) if tasks else []
    for result in tqdm(results, total=len(tasks), desc="outfits", unit="outfit"):
        if result["ok"]:
            built.add(result["name"])
        else:
            failed[result["name"]] = result["reason"]
            log(f"outfit {result['name']} left out: {result['reason']}")
    return {plan.name: {"split": plan.sequence.split, "sequence": plan.sequence.name,
                        "garments": list(plan.garments)}
            for plan in planned if plan.name in built}


def _warm_up_kernels(log: Callable[[str], None]) -> None:
    """Compile Warp's kernels once in this process (a tiny simulation), so the workers
    load them from the on-disk kernel cache instead of all compiling at the same time
    (~25-45 s on an empty cache, seconds afterwards)."""
    import trimesh

    from data_prep.garments.skirt import flared_skirt
    from data_prep.simulate import SimulationSettings, simulate_garment

    started = time.perf_counter()
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.1)
    body = np.repeat(np.asarray(sphere.vertices)[None], 2, axis=0)
    pos, faces = flared_skirt(60, waist_radius=0.12, hem_radius=0.2, length=0.1,
                              waist_height=0.05)
    simulate_garment(pos, faces, body, np.asarray(sphere.faces), 30.0,
                     settings=SimulationSettings(settle_frames=0, max_retries=0,
                                                 max_edge_stretch=100.0,
                                                 max_inside_fraction=1.0))
    log(f"simulation kernels ready ({time.perf_counter() - started:.0f} s)")
