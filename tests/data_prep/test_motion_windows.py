"""Motion-capture clips in a dataset plan: windows, the split by subject, held-out pairs
with several motions, and a clip window's motion (lead-in from rest, held last pose)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from data_prep.config import DataConfig, SplitConfig
from data_prep.inputs_hash import sequence_inputs_hash
from data_prep.motion_windows import (
    clip_duration,
    clip_subject,
    clip_windows,
    find_clips,
    interleave_by_subject,
)
from data_prep.plan import plan_dataset, planned_motion
from tests.body.test_bvh_motion import CMU131, _frames_from_rotations, _random_motion, _write_bvh


def _clip(path: Path, seconds: float, seed: int = 0, fps: float = 30.0) -> Path:
    frames = round(seconds * fps) + 1
    root, local = _random_motion(CMU131, frames=frames, seed=seed, spread=0.3)
    _write_bvh(path, CMU131, _frames_from_rotations(CMU131, root, local), frame_time=1 / fps)
    return path


@pytest.fixture
def clips(tmp_path: Path) -> Path:
    folder = tmp_path / "clips"
    folder.mkdir()
    for k, (name, seconds) in enumerate({"01_01": 5.0, "01_02": 1.0, "02_01": 3.0,
                                         "03_01": 4.5, "03_02": 2.5, "04_01": 2.2}.items()):
        _clip(folder / f"{name}.bvh", seconds, seed=k)
    (folder / "notes.txt").write_text("not a clip")
    return folder


def _config(clips: Path, **changes) -> DataConfig:
    base = DataConfig(garments=8, bodies=4, motions=["walk", "squat", "twist", "run", "wave"],
                      motions_per_pair=3, motion_files=[str(clips)], motion_window_seconds=2.0,
                      windows_per_clip=2, held_out_motions_per_pair=2,
                      splits=SplitConfig(val_garments=1, test_garments=2, val_bodies=1,
                                         test_bodies=1, val_motions=1, test_motions=1,
                                         val_subjects=["02"], test_subjects=["03", "04"]))
    return replace(base, **changes)


def test_clip_subject_and_discovery(clips: Path) -> None:
    assert clip_subject("cmu/09_01.bvh") == "09" and clip_subject("dance.npz") == "dance"
    found = find_clips([str(clips)])
    assert [p.name for p in found] == ["01_01.bvh", "01_02.bvh", "02_01.bvh", "03_01.bvh",
                                       "03_02.bvh", "04_01.bvh"]
    assert abs(clip_duration(found[0]) - 5.0) < 1e-4  # frame time written rounded
    with pytest.raises(ValueError, match="notes.txt is not a"):
        find_clips([str(clips / "notes.txt")])
    with pytest.raises(ValueError, match="missing.bvh not found"):
        find_clips([str(clips / "missing.bvh")])


def test_windows_lie_in_their_clip_and_are_seeded(clips: Path) -> None:
    found = find_clips([str(clips)])
    windows = clip_windows(found, 2.0, 2, seed=3)
    assert windows == clip_windows(found, 2.0, 2, seed=3)
    assert windows != clip_windows(found, 2.0, 2, seed=4)
    for window in windows:
        duration = clip_duration(Path(window.file))
        assert window.start >= 0 and window.start + window.seconds <= duration + 0.01
    per_clip = {Path(w.file).stem: sum(1 for v in windows if v.file == w.file) for w in windows}
    # 5 s and 4.5 s give two windows, 3 s and 2.5 s one of 2 s, 1 s the whole clip.
    assert per_clip == {"01_01": 2, "01_02": 1, "02_01": 1, "03_01": 2, "03_02": 1, "04_01": 1}
    assert next(w for w in windows if w.file.endswith("01_02.bvh")).seconds == 1.0
    ordered = interleave_by_subject(windows)
    assert sorted(ordered, key=str) == sorted(windows, key=str)
    assert [w.subject for w in ordered[:4]] == ["01", "02", "03", "04"]


def test_plan_splits_clips_by_subject(clips: Path) -> None:
    config = _config(clips)
    plans = plan_dataset(config)
    assert plans == plan_dataset(config)
    subjects = {split: {p.motion.subject for p in plans if p.split == split and p.motion.is_clip}
                for split in ("train", "val", "test")}
    assert subjects == {"train": {"01"}, "val": {"02"}, "test": {"03", "04"}}
    pairs: dict = {}
    for plan in plans:
        pairs.setdefault((plan.split, plan.garment), []).append(plan.motion)
    for (split, _), motions in pairs.items():
        # Every pair: its first motion procedural, then clip windows.
        assert not motions[0].is_clip and all(m.is_clip for m in motions[1:]), motions
        # Held out: 2 windows a pair where the split has them (val: subject 02's one).
        assert len(motions) == {"train": 3, "val": 2, "test": 3}[split]
    test_windows = {p.motion.name for p in plans if p.split == "test" and p.motion.is_clip}
    assert len(test_windows) == 4  # two test pairs × 2 windows, all different


def test_plan_refuses_unknown_or_all_held_out_subjects(clips: Path) -> None:
    with pytest.raises(ValueError, match=r"subjects \['99'\] have no clip"):
        plan_dataset(_config(clips, splits=replace(_config(clips).splits, test_subjects=["99"])))
    with pytest.raises(ValueError, match="every subject of motion_files is held out"):
        plan_dataset(_config(clips, splits=replace(_config(clips).splits,
                                                   val_subjects=["01", "02"])))


def test_clip_fields_leave_procedural_hashes_alone(clips: Path) -> None:
    """A build made before clips existed resumes: a procedural sequence's hash does not
    see the new plan fields, a clip's hash sees its file's content."""
    config = _config(clips)
    procedural = next(p for p in plan_dataset(config) if not p.motion.is_clip)
    clip = next(p for p in plan_dataset(config) if p.motion.is_clip)
    inputs = {"config": "same"}
    old_style = replace(procedural.motion)
    assert sequence_inputs_hash(inputs, procedural) == sequence_inputs_hash(
        inputs, replace(procedural, motion=old_style))
    changed = replace(clip, motion=replace(clip.motion, digest="0" * 64))
    assert sequence_inputs_hash(inputs, changed) != sequence_inputs_hash(inputs, clip)


def test_clip_window_starts_at_rest_and_holds_its_last_pose(clips: Path) -> None:
    from gnngarment.body.anny_model import AnnyBodyModel

    config = _config(clips, lead_in_seconds=0.5, hold_seconds=0.4)
    plan = next(p for p in plan_dataset(config) if p.motion.is_clip and p.motion.seconds == 2.0)
    motion = planned_motion(plan.motion, config, AnnyBodyModel(), None)
    assert motion.fps == config.fps
    lead, hold = round(0.5 * config.fps), round(0.4 * config.fps)
    assert abs(len(motion) - (lead + round(2.0 * config.fps) + 1 + hold)) <= 2
    np.testing.assert_allclose(motion.rotations[0], 0.0, atol=1e-9)
    np.testing.assert_allclose(motion.translation[0], 0.0, atol=1e-9)
    for k in range(1, hold + 1):
        np.testing.assert_allclose(motion.rotations[-k], motion.rotations[-1])
    with pytest.raises(ValueError, match="needs the body"):
        planned_motion(plan.motion, config)


@pytest.mark.parametrize(("key", "value"), [("motion_seconds", 1e9), ("fps", 1e6),
                                            ("levels", 100), ("lead_in_seconds", -1.0),
                                            ("windows_per_clip", 0)])
def test_config_refuses_out_of_range_values(key: str, value: float) -> None:
    with pytest.raises(ValueError, match=f"key '{key}'"):
        DataConfig(**{key: value})
