"""`_backend`: Warp and Newton are imported lazily, so importing the package loads neither."""

from __future__ import annotations

from tests.fresh_interpreter import run_in_fresh_interpreter


def test_importing_the_package_loads_neither_warp_nor_newton() -> None:
    code = ("import sys, data_prep.simulate; "
            "print(sorted(m for m in ('warp', 'newton') if m in sys.modules))")
    assert run_in_fresh_interpreter(code).strip() == "[]"
