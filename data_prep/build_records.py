"""What a build records and reads back of its tasks: the status dict of each (built, left
out, crashed, lost), the ``.failed`` records that keep a resumed build from repeating a
failure with the same inputs, whether a drape or sequence is already built (its hash
matches and its ``.npz`` is whole), and the losses of a build counted by reason."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from data_prep.garment_fitting import read_pins
from data_prep.plan import OutfitPlan, SequencePlan
from gnngarment.io.atomic import atomic_write_bytes


def crashed(name: str, error: Exception, started: float) -> dict[str, Any]:
    """The status dict of a worker task that raised: the error and where it was raised."""
    import traceback

    where = traceback.extract_tb(error.__traceback__)[-1]
    return {"name": name, "ok": False,
            "reason": f"{type(error).__name__}: {error} ({Path(where.filename).name}:"
                      f"{where.lineno})", "seconds": time.perf_counter() - started}


def left_out(root: Path, name: str, inputs_hash: str, reason: str,
             started: float, kind: str = "sequences") -> dict[str, Any]:
    """Record a sequence (``kind="garments"``: a garment's drape) that failed its quality
    gates (with its input hash, so that a resumed build does not simulate it again) and
    return its status dict."""
    folder = root / kind
    folder.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(folder / f"{name}.failed",
                       json.dumps({"inputs_hash": inputs_hash, "reason": reason}).encode())
    return {"name": name, "ok": False, "reason": reason,
            "seconds": time.perf_counter() - started}


def known_failure(root: Path, name: str, inputs_hash: str,
                  folder: str = "sequences") -> str | None:
    """The recorded reason a sequence (or, with ``folder="garments"``, a garment's drape)
    with these inputs failed before, if any."""
    path = root / folder / f"{name}.failed"
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return record.get("reason") if record.get("inputs_hash") == inputs_hash else None


def _intact_npz(path: Path) -> bool:
    """Whether ``path`` is a whole ``.npz``: its zip directory reads and every member
    matches its CRC (a truncated or damaged file is rebuilt, not counted as built)."""
    import zipfile

    try:
        with zipfile.ZipFile(path) as archive:
            return archive.testzip() is None
    except (OSError, EOFError, zipfile.BadZipFile):
        return False


def garment_done(root: Path, name: str, inputs_hash: str) -> bool:
    hash_file = root / "garments" / f"{name}.hash"
    return ((root / "garments" / f"{name}.npz").is_file()
            and (root / "garments" / f"{name}.pins.json").is_file()
            and hash_file.is_file() and hash_file.read_text() == inputs_hash
            and _intact_npz(root / "garments" / f"{name}.npz"))


def garment_summary(root: Path, name: str) -> dict[str, Any]:
    """What the build report says of a garment draped by an earlier run."""
    from gnngarment.data.cache import read_garment

    record = read_garment(root, name)
    shift = (np.linalg.norm(record.rest_pos - record.design_pos, axis=1).mean()
             if record.design_pos is not None else float("nan"))
    return {"name": name, "ok": True, "vertices": len(record.rest_pos),
            "faces": len(record.faces), "pinned": len(read_pins(root, name)[0]),
            "drape_mean_displacement_mm": 1000 * float(shift)}


def sequence_done(root: Path, name: str, inputs_hash: str, folder: str = "sequences") -> bool:
    """Whether a sequence (``folder="outfits"``: an outfit) is built with these inputs."""
    hash_file = root / folder / f"{name}.hash"
    return ((root / folder / f"{name}.npz").is_file() and hash_file.is_file()
            and hash_file.read_text() == inputs_hash
            and _intact_npz(root / folder / f"{name}.npz"))


def lost_task(task: tuple, error: Exception) -> dict[str, Any]:
    """The status of a task whose worker process died more often than Ray retries it:
    left out of this build, not recorded as failed (the next build tries it again)."""
    plan = task[1]
    name = (plan.name if isinstance(plan, SequencePlan | OutfitPlan)
            else f"{plan.name}_{task[2].name}")
    return {"name": name, "ok": False, "reason": f"worker lost: {type(error).__name__}",
            "seconds": math.nan}


#: Reason a planned sequence was lost → the words that identify it in its message.
LOSS_REASONS = {
    "drape failed": ("drape:",),
    "left the body": ("slid off the body",),
    "fell down the body": ("fell down the body",),
    "edge stretch": ("stretch",),
    "inside the body": ("inside",),
    "not finite": ("non-finite",),
}


def losses_by_reason(failed_sequences: dict[str, str], failed_garments: dict[str, str],
                     plans: list[SequencePlan]) -> dict[str, int]:
    """How many planned sequences each kind of failure removed (a failed garment drape
    removes all of its sequences), plus ``planned`` and ``lost`` in total."""
    counts: dict[str, int] = {}

    def count(reason: str) -> None:
        kind = next((k for k, words in LOSS_REASONS.items()
                     if any(w in reason for w in words)), "other")
        counts[kind] = counts.get(kind, 0) + 1

    for plan in plans:
        if plan.garment in failed_garments:
            count(failed_garments[plan.garment])
        elif plan.name in failed_sequences:
            count(failed_sequences[plan.name])
    return {"planned": len(plans), "lost": sum(counts.values()), **counts}
