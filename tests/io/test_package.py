"""``gnngarment.io`` sits below every other package: it imports nothing else of ours."""

from tests.fresh_interpreter import run_in_fresh_interpreter


def test_io_modules_load_only_numpy_and_themselves() -> None:
    code = ("import sys\n"
            "import gnngarment.io.atomic, gnngarment.io.npz, gnngarment.io.obj, "
            "gnngarment.io.point_cache\n"
            "ours = sorted(m for m in sys.modules if m.startswith('gnngarment') "
            "and m != 'gnngarment' and not m.startswith('gnngarment.io'))\n"
            "assert not ours, ours\n"
            "assert 'torch' not in sys.modules and 'scipy' not in sys.modules\n")
    run_in_fresh_interpreter(code)
