"""glibc's allocator set to keep freed memory for reuse: tens of percent of the
per-frame network's time on CPU.

By default glibc serves every allocation above 128 KiB (up to 32 MiB, adapting) with a
fresh ``mmap`` and unmaps it on ``free``. A batch of 16 frames of a 5,000-vertex garment
makes and frees dozens of 10-40 MB tensors per pass, and each fresh one pays a page
fault per 4 KiB page on first touch: measured, a ``(80000, 32) @ (32, 128)`` product took
18 ms into a fresh tensor and 3.6 ms into a reused one. ``mallopt(M_MMAP_MAX, 0)``
serves large blocks from the heap instead, and a high ``M_TRIM_THRESHOLD`` keeps freed
ones there, so the next pass reuses pages already mapped (docs/experiments/
2026-12-03-speed-issue14.md, item 10). Unlike the ``MALLOC_MMAP_THRESHOLD_``
environment variable this can be set at run time, so every ``gnngarment`` command sets it at start.

The cost: memory freed by the process stays mapped, up to :data:`TRIM_THRESHOLD`
above what it uses (its peak resident memory is what it would have been). A library
that only imports gnngarment is left alone unless it calls :func:`keep_freed_memory`.
Set ``GNNGARMENT_KEEP_FREED_MEMORY=0`` to turn it off.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os

#: ``mallopt`` parameters (``<malloc.h>``).
M_TRIM_THRESHOLD = -1
M_MMAP_MAX = -4
#: Freed memory at the top of the heap kept for reuse before it is returned (bytes).
TRIM_THRESHOLD = 512 * 2**20
#: Environment variable that turns :func:`keep_freed_memory` off when ``"0"``.
SWITCH = "GNNGARMENT_KEEP_FREED_MEMORY"


def keep_freed_memory() -> bool:
    """Make glibc keep large freed blocks for reuse (see the module docstring).

    Returns whether the setting was applied: ``False`` where the C library is not glibc
    (macOS, Windows, musl), or when ``GNNGARMENT_KEEP_FREED_MEMORY=0``.
    """
    if os.environ.get(SWITCH, "1") == "0":
        return False
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
        libc.gnu_get_libc_version  # noqa: B018 - present only in glibc
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    mallopt.restype = ctypes.c_int
    return bool(mallopt(M_MMAP_MAX, 0)) and bool(mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD))
