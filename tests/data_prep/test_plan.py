"""The dataset plan: deterministic, validation and test sequences hold out designs, bodies
and motions, and the training motions of the shipped configs move every joint."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from data_prep.config import DataConfig
from data_prep.plan import plan_dataset
from gnngarment.config import load_config
from gnngarment.paths import REPOSITORY_ROOT


def test_plan_holds_out_garments_bodies_and_motions(tmp_path: Path) -> None:
    config = load_config(REPOSITORY_ROOT / "configs" / "data" / "demo.yaml", DataConfig)
    plans = plan_dataset(config)
    assert plans == plan_dataset(config)  # deterministic
    train = [p for p in plans if p.split == "train"]
    for split in ("val", "test"):
        held = [p for p in plans if p.split == split]
        assert held, split
        for attribute in ("design", "body", "motion"):
            seen = {getattr(p, attribute).name for p in train}
            assert not {getattr(p, attribute).name for p in held} & seen, (split, attribute)


@pytest.mark.parametrize("config_name", ["demo", "benchmark"])
def test_training_motions_move_every_joint(config_name: str) -> None:
    """Real mocap moves the neck, collars, head, wrists and hands; training data that
    never moves them cannot show that they leave trousers alone (issue 12 §2). Over the
    training motions of the config, every joint turns at least 15° from the rest pose."""
    from scipy.spatial.transform import Rotation

    from gnngarment.body.procedural import make_motion
    from gnngarment.body.skeleton import JOINT_NAMES

    config = load_config(REPOSITORY_ROOT / "configs" / "data" / f"{config_name}.yaml",
                         DataConfig)
    motions = {p.motion for p in plan_dataset(config) if p.split == "train"}
    largest = np.zeros(len(JOINT_NAMES))
    for plan in motions:
        motion = make_motion(plan.motion, duration=config.motion_seconds, fps=config.fps,
                             seed=plan.seed)
        angles = Rotation.from_rotvec(motion.rotations.reshape(-1, 3)).magnitude()
        largest = np.maximum(largest, np.degrees(angles.reshape(len(motion), -1)).max(0))
    still = {name: round(float(deg), 1) for name, deg in zip(JOINT_NAMES, largest, strict=True)
             if deg < 15.0}
    assert not still, f"joints that turn less than 15° in {config_name}'s training motions: {still}"


def test_outfits_pair_a_test_bottom_and_top_on_one_body_and_the_bottoms_motions() -> None:
    """Each planned outfit wears a test top over a test bottom draped on the same test
    body, on a held-out motion of one of the bottom's own test sequences; the plan is
    deterministic, capped by ``outfits``, and empty with ``outfits: 0``."""
    from dataclasses import replace

    from data_prep.plan import BOTTOM_TYPES, TOP_TYPES, plan_outfits

    config = load_config(REPOSITORY_ROOT / "configs" / "data" / "benchmark_cmu.yaml", DataConfig)
    assert plan_outfits(replace(config, outfits=0)) == []
    config = replace(config, outfits=3)
    plans = plan_dataset(config)
    outfits = plan_outfits(config, plans)
    assert outfits == plan_outfits(config)
    tests = {p.name: p for p in plans if p.split == "test"}
    pairs = {(o.sequence.design.name, o.top.name) for o in outfits}
    assert len(pairs) == 3
    for outfit in outfits:
        assert outfit.sequence.name in tests
        assert outfit.sequence.design.garment_type in BOTTOM_TYPES
        assert outfit.top.garment_type in TOP_TYPES and outfit.top.split == "test"
        # The top is draped on the same body (one of its own test sequences uses it).
        assert any(p.design == outfit.top and p.body.name == outfit.sequence.body.name
                   for p in tests.values())
    # Every held-out motion of a chosen bottom's sequences on that body is an outfit.
    for bottom, top in pairs:
        body = next(o.sequence.body.name for o in outfits if o.top.name == top)
        motions = {p.motion.name for p in tests.values()
                   if p.design.name == bottom and p.body.name == body}
        assert {o.sequence.motion.name for o in outfits
                if o.top.name == top and o.sequence.design.name == bottom} == motions
