"""Motion-capture clips as dataset motions: files and folders found, each clip's subject
read from its name, and every clip cut into seeded windows of a configured length.

A build's real motions are *windows* of clips (a 20 s CMU clip gives several sequences;
a 1.1 s run gives one, the whole clip). Splits go by **subject** (the performer): no
test subject's clip is seen in training. A clip's subject is the part of its file name
before the first ``_`` (CMU's ``SS_CC.bvh``: subject ``SS``, clip ``CC``), the whole
stem when there is none.

Pure planning: nothing here poses a body or reads more of a file than its frame count.
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: Motion files a build reads (the formats :func:`gnngarment.body.load_motion` reads
#: that carry a whole clip; CLOTH3D's ``info.mat`` comes with its own garments).
CLIP_SUFFIXES = (".bvh", ".npz")


@dataclass(frozen=True)
class MotionWindow:
    """One window of a clip: ``seconds`` of ``file`` from ``start`` (seconds).

    Attributes:
        file: the clip's path as the config names it (relative to the working folder).
        subject: the clip's performer (:func:`clip_subject`).
        start, seconds: the window, in the clip's own time (seconds).
        digest: sha256 of the file's bytes (a changed file rebuilds its sequences).
    """

    file: str
    subject: str
    start: float
    seconds: float
    digest: str

    @property
    def name(self) -> str:
        """``clip09_01t0125``: the clip's stem and the window's start in centiseconds."""
        stem = re.sub(r"[^A-Za-z0-9_]", "", Path(self.file).stem)
        return f"clip{stem}t{round(self.start * 100):04d}"


def clip_subject(path: str | Path) -> str:
    """The performer of a clip, from its file name: ``09_01.bvh`` → ``"09"``."""
    stem = Path(path).stem
    return stem.split("_", 1)[0] if "_" in stem else stem


def find_clips(entries: list[str]) -> list[Path]:
    """Every clip the config's ``motion_files`` name: files as given, folders expanded to
    their ``.bvh``/``.npz`` files (not recursively), sorted by name.

    Raises:
        ValueError: an entry that does not exist, a file of another type, or a folder
            without clips; the message names the entry.
    """
    clips: list[Path] = []
    for entry in entries:
        path = Path(entry)
        if path.is_dir():
            found = sorted(p for p in path.iterdir()
                           if p.is_file() and p.suffix.lower() in CLIP_SUFFIXES)
            if not found:
                raise ValueError(f"key 'motion_files': folder {entry} holds no "
                                 f"{'/'.join(CLIP_SUFFIXES)} clips")
            clips.extend(found)
        elif path.is_file():
            if path.suffix.lower() not in CLIP_SUFFIXES:
                raise ValueError(f"key 'motion_files': {entry} is not a "
                                 f"{'/'.join(CLIP_SUFFIXES)} file")
            clips.append(path)
        else:
            raise ValueError(f"key 'motion_files': {entry} not found (a motion file or a "
                             "folder of them; relative paths start at the working folder)")
    return clips


def clip_duration(path: Path) -> float:
    """Seconds between a clip's first and last frame, from its header (BVH ``Frames:`` and
    ``Frame Time:``) or its arrays (``.npz``: ``poses`` and ``fps``/``mocap_framerate``).

    Raises:
        ValueError: the header or arrays are missing or not numbers (naming the file).
    """
    if path.suffix.lower() == ".bvh":
        frames = frame_time = None
        with path.open(errors="replace") as handle:
            for line in handle:
                if line.startswith("Frames:"):
                    frames = line.split(":", 1)[1]
                elif line.startswith("Frame Time:"):
                    frame_time = line.split(":", 1)[1]
                    break
        try:
            count, step = int(str(frames).strip()), float(str(frame_time).strip())
        except ValueError:
            raise ValueError(f"{path}: no readable 'Frames:'/'Frame Time:' header") from None
        if count < 1 or not 0 < step < 10:
            raise ValueError(f"{path}: header says {count} frames of {step} s")
        return (count - 1) * step
    with np.load(path, allow_pickle=False) as data:
        rate_key = next((k for k in ("fps", "mocap_framerate") if k in data.files), None)
        if "poses" not in data.files or rate_key is None:
            raise ValueError(f"{path}: an .npz clip needs 'poses' and 'fps' (or "
                             "'mocap_framerate')")
        try:
            rate = float(data[rate_key])
        except (TypeError, ValueError):
            raise ValueError(f"{path}: '{rate_key}' is not a number") from None
        if not 0 < rate < 10_000:
            raise ValueError(f"{path}: '{rate_key}' must be in (0, 10000) frames/s, got {rate}")
        return (int(data["poses"].shape[0]) - 1) / rate


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def clip_windows(clips: list[Path], window_seconds: float, windows_per_clip: int,
                 seed: int) -> list[MotionWindow]:
    """The windows of every clip: a clip no longer than ``window_seconds`` is one window
    (the whole clip); a longer one gives up to ``windows_per_clip`` windows of that length
    at seeded start times, as far apart as its length allows (a clip shorter than two
    windows gives one). Deterministic in ``seed`` and each clip's name, so adding a clip
    keeps every other clip's windows."""
    windows = []
    for path in clips:
        duration, digest = clip_duration(path), _digest(path)
        subject = clip_subject(path)
        if duration <= window_seconds:
            windows.append(MotionWindow(str(path), subject, 0.0, round(duration, 4), digest))
            continue
        count = max(1, min(windows_per_clip, int(duration // window_seconds)))
        # One stratum per window: window k starts in [k, k + 1) · slack / count, so
        # windows overlap as little as the clip allows and never start past its end.
        slack = duration - window_seconds
        rng = np.random.default_rng([seed, int(digest[:8], 16)])
        starts = (np.arange(count) + rng.uniform(size=count)) * slack / count
        windows += [MotionWindow(str(path), subject, round(float(s), 2), window_seconds, digest)
                    for s in starts]
    return windows


def interleave_by_subject(windows: list[MotionWindow]) -> list[MotionWindow]:
    """Windows reordered round-robin over subjects (each subject's in clip order), so
    that the first ``k`` cover as many subjects and clips as ``k`` allows."""
    by_subject: dict[str, list[MotionWindow]] = {}
    for window in windows:
        by_subject.setdefault(window.subject, []).append(window)
    queues = []
    for subject in sorted(by_subject):
        # Within a subject: first windows of every clip, then second windows, ...
        clip_order: dict[str, list[MotionWindow]] = {}
        for window in by_subject[subject]:
            clip_order.setdefault(window.file, []).append(window)
        rounds = max(len(v) for v in clip_order.values())
        queues.append([w for r in range(rounds) for v in clip_order.values()
                       if r < len(v) for w in [v[r]]])
    ordered = []
    for r in range(max((len(q) for q in queues), default=0)):
        ordered += [q[r] for q in queues if r < len(q)]
    return ordered
