"""The documented limits of a motion, checked before any frame is built: beyond them a
request is a typo or an attack (``--fps 1e9`` asked this machine for 9.8 GB), not a use.

docs/reliability.md ("Resource limits") lists them with their reasons.
"""

from __future__ import annotations

import math

#: Frames per second a motion file may declare: mocap runs at 30–250 Hz, and a clip is
#: resampled to the output rate anyway.
MAX_SOURCE_FPS = 1000.0
#: Output frames per second (``--fps``): 240 is beyond any display or engine.
MAX_FPS = 240.0
#: Seconds of a procedural motion (``--duration``): ten minutes.
MAX_MOTION_SECONDS = 600.0
#: Fewest frames an animation may have: one frame is a pose, not a motion.
MIN_FRAMES = 2


def motion_option_problem(fps: float, duration: float) -> str | None:
    """What is wrong with ``--fps`` / ``--duration`` (naming the option), or ``None``."""
    for option, value in (("--fps", fps), ("--duration", duration)):
        if not (value > 0 and math.isfinite(value)):  # also NaN, which `<= 0` lets through
            return f"{option} must be a finite number > 0, got {value}"
    if fps > MAX_FPS:
        return f"--fps must be at most {MAX_FPS:g} frames per second, got {fps:g}"
    if duration > MAX_MOTION_SECONDS:
        return f"--duration must be at most {MAX_MOTION_SECONDS:g} s, got {duration:g}"
    if fps * duration < MIN_FRAMES:
        return (f"--fps {fps:g} x --duration {duration:g} s gives fewer than {MIN_FRAMES} "
                "frames (a motion needs at least two)")
    return None
