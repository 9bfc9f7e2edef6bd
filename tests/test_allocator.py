"""The allocator setting keeps freed large blocks mapped (and can be turned off)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not Path("/proc/self/status").exists(),
                                reason="needs Linux's /proc to read resident memory")

# A child process: the setting is process-wide, and the test process must keep its own.
CHILD = """
import numpy as np
from gnngarment.allocator import keep_freed_memory

def resident_mb():
    for line in open("/proc/self/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024

applied = keep_freed_memory()
block = np.ones(64 * 2**20 // 8)          # 64 MB, touched
before = resident_mb()
del block
print(applied, before - resident_mb())
"""


def freed_after_delete(switch: str | None) -> tuple[bool, float]:
    env = dict(os.environ)
    env.pop("GNNGARMENT_KEEP_FREED_MEMORY", None)
    if switch is not None:
        env["GNNGARMENT_KEEP_FREED_MEMORY"] = switch
    done = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True,
                          env=env, check=True)
    applied, released = done.stdout.split()
    return applied == "True", float(released)


def test_freed_block_stays_mapped_for_reuse() -> None:
    applied, released = freed_after_delete(None)
    if not applied:
        pytest.skip("the C library is not glibc: nothing to set")
    assert released < 8, f"{released:.0f} MB returned to the system"


def test_switch_turns_it_off() -> None:
    applied, released = freed_after_delete("0")
    assert not applied
    assert released > 56, f"only {released:.0f} MB of the 64 MB block was unmapped"
