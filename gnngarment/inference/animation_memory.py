"""How much memory ``animate`` will need, estimated before any frame is built.

The fps and duration limits (:mod:`gnngarment.body.motion_limits`) bound each option on
its own; their product with the garment's size can still ask for more memory than the
machine has (600 s at 240 fps is 144,000 frames: ~520 GB for a 5,000-vertex garment).
``animate`` keeps every frame of the garment and the posed body, their exports and the
GIF's rendered frames until it writes them, so its memory grows linearly with the
frames, with a per-frame cost of a body part and a garment part.

The two constants were measured as peak resident memory (``/usr/bin/time -f %M``) of
``gnngarment animate --duration 2`` and ``--duration 10`` (default formats, the body
exported) on the SNUG shorts (2,364 vertices: 2.41 MB per frame) and the DiffCloth
dress (5,563 vertices: 3.74 MB per frame), AMD EPYC, 2026-12-06.
"""

from __future__ import annotations

import os
from pathlib import Path

#: Bytes per frame that do not depend on the garment: the posed body mesh, its exports
#: and the GIF frame.
BODY_BYTES_PER_FRAME = 1.45e6
#: Bytes per garment vertex and frame (predictions, collision pass, exports).
GARMENT_BYTES_PER_VERTEX_FRAME = 420.0
#: Share of the available memory a run may plan to use: the model, the process and
#: the rest of the machine need the remainder.
USABLE_SHARE = 0.8


def animation_bytes(frames: int, garment_vertices: int) -> float:
    """Estimated peak memory (bytes) of animating ``garment_vertices`` over ``frames``."""
    return frames * (BODY_BYTES_PER_FRAME + GARMENT_BYTES_PER_VERTEX_FRAME * garment_vertices)


def available_bytes() -> float | None:
    """Memory the machine can give this process now (``MemAvailable``), or ``None`` where
    the system does not say."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        return None


def animation_memory_problem(frames: int, garment_vertices: int,
                             available: float | None = None) -> str | None:
    """Why animating ``frames`` frames of a ``garment_vertices``-vertex garment would not
    fit in memory (a line naming the options that set the frame count), or ``None``.

    Args:
        available: bytes available (default: :func:`available_bytes`; ``None`` there
            means unknown, and nothing is refused).
    """
    available = available_bytes() if available is None else available
    if available is None:
        return None
    needed = animation_bytes(frames, garment_vertices)
    if needed <= USABLE_SHARE * available:
        return None
    fitting = int(USABLE_SHARE * available / (needed / frames))
    what = (f"{frames} frames x {garment_vertices} garment vertices" if garment_vertices
            else f"{frames} frames of the posed body")
    return (f"{what} need about "
            f"{needed / 1e9:.1f} GB, more than this machine has free "
            f"({available / 1e9:.1f} GB available); shorten the motion (--duration, or a "
            f"shorter --motion file) or lower --fps: at most about {fitting} frames fit")
