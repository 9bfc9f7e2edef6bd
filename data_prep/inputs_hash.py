"""The inputs hash of every sequence and drape a build makes: what its content depends
on, hashed. A built file is recorded with it (its ``.hash`` file, or in its ``.failed``
record), so a resumed build skips what it would only make again and redoes what changed.

The payloads are a file format: existing caches are resumed by these hashes, so a change
to what is hashed rebuilds every cache (that is what :data:`BUILDER_VERSION` is for).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict
from typing import Any

from data_prep.config import DataConfig
from data_prep.plan import CLIP_FIELDS, BodyPlan, DesignPlan, OutfitPlan, SequencePlan

#: Bumped when the builder's output changes for the same config (forces a rebuild).
BUILDER_VERSION = 1

#: Config keys that only decide *which* garments, bodies and motions are planned: their
#: effect on a sequence is all in its plan (hashed with it), so changing them (e.g. more
#: motions per pair) keeps every sequence and drape already built.
PLAN_KEYS = ("seed", "garment_types", "garments", "extra_train_garments",
             "extra_val_garments", "extra_test_garments",
             "garment_vertices", "bodies",
             "body_presets", "motions", "motions_per_pair", "motion_variants", "fabrics",
             "splits", "motion_files", "motion_window_seconds", "windows_per_clip",
             "lead_in_seconds", "hold_seconds", "held_out_motions_per_pair", "outfits")
#: Config keys that decide nothing a worker computes.
PLACE_KEYS = ("output", "workers", "simulation", "executor", "ray_address")


def content_inputs(config: DataConfig, settings: Any) -> dict[str, Any]:
    """What every sequence's and drape's content depends on besides its own plan: not
    where the dataset lives, how many processes build it or where, the path of the
    simulation file (its ``settings`` are hashed), nor what only chooses the plans."""
    content = {k: v for k, v in asdict(config).items() if k not in PLACE_KEYS + PLAN_KEYS}
    return {"builder": BUILDER_VERSION, "config": content, "simulation": asdict(settings)}


def sequence_inputs_hash(inputs: dict[str, Any], plan: SequencePlan) -> str:
    """The hash a built sequence is recorded with (its ``.hash`` file). A canonical
    motion (tempo and amplitude 1) is hashed without those two fields, a procedural one
    without the clip fields (so hashes of builds before clips existed still hold); a
    clip's window, lead-in, hold and file digest are in its plan."""
    fields = asdict(plan)
    fields["motion"] = {key: value for key, value in fields["motion"].items()
                        if not (key in ("speed", "amplitude") and value == 1.0)
                        and not (key in CLIP_FIELDS and not fields["motion"]["file"])}
    return _hash({**inputs, "plan": fields})


def garment_inputs_hash(inputs: dict[str, Any], design: DesignPlan, body: BodyPlan) -> str:
    """The hash a draped garment (``design`` fitted to ``body``) is recorded with."""
    return _hash({**inputs, "design": asdict(design), "body": asdict(body)})


def outfit_inputs_hash(inputs: dict[str, Any], plan: OutfitPlan) -> str:
    """The hash a built outfit is recorded with: its bottom's sequence plan and its top's
    design (the bodies, motion and drapes follow from them)."""
    return _hash({**inputs, "outfit": {"sequence": asdict(plan.sequence),
                                       "top": asdict(plan.top)}})


def _hash(payload: Any) -> str:
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()
