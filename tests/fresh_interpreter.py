"""Run a snippet in a new Python process: what a package loads on import, or what it
does lazily, can only be seen before this test session imported it."""

from __future__ import annotations

import subprocess
import sys


def run_in_fresh_interpreter(code: str, *args: str) -> str:
    """Run ``code`` (with ``sys.argv[1:] = args``) in this interpreter's executable; its
    stdout. Fails the test with the snippet's stderr if it exits non-zero."""
    result = subprocess.run([sys.executable, "-c", code, *args], capture_output=True,
                            text=True)
    assert result.returncode == 0, result.stderr[-2000:]
    return result.stdout
