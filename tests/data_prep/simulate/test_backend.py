"""`_backend`: Warp and Newton are imported lazily, so importing the package loads neither."""

from __future__ import annotations

import subprocess
import sys


def test_importing_the_package_loads_neither_warp_nor_newton() -> None:
    code = ("import sys, data_prep.simulate; "
            "print(sorted(m for m in ('warp', 'newton') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
