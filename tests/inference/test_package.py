"""The package's lazy exports (issue 16: ``gnngarment.inference.Animation`` recursed and
``animate`` named the module once it was loaded)."""

from tests.fresh_interpreter import run_in_fresh_interpreter


def test_lazy_exports_are_the_objects_in_a_fresh_interpreter() -> None:
    code = ("import inspect, gnngarment.inference as package\n"
            "assert inspect.isclass(package.Animation)\n"
            "assert inspect.isfunction(package.animate), package.animate\n"
            "assert inspect.isfunction(package.garment_pair)\n"
            "from gnngarment.inference.animate import animate\n"
            "assert package.animate is animate\n")
    run_in_fresh_interpreter(code)
