"""The memory estimate animate checks before it builds any frame."""

from __future__ import annotations

from gnngarment.inference.animation_memory import (
    animation_bytes,
    animation_memory_problem,
    available_bytes,
)


def test_the_estimate_grows_with_frames_and_vertices_and_matches_the_measurements() -> None:
    # Measured: 2.41 MB per frame (2,364 vertices), 3.74 MB (5,563 vertices).
    assert abs(animation_bytes(1, 2364) / 2.41e6 - 1) < 0.05
    assert abs(animation_bytes(1, 5563) / 3.74e6 - 1) < 0.05
    assert animation_bytes(200, 1000) == 2 * animation_bytes(100, 1000)


def test_what_fits_passes_and_what_does_not_is_refused_with_what_would_fit() -> None:
    assert animation_memory_problem(60, 5000, available=20e9) is None
    problem = animation_memory_problem(144_000, 5000, available=20e9)
    assert problem is not None and "144000 frames x 5000 garment vertices" in problem
    fitting = int(problem.rsplit("at most about ", 1)[1].split()[0])
    assert animation_memory_problem(fitting, 5000, available=20e9) is None
    assert animation_memory_problem(fitting + 100, 5000, available=20e9) is not None


def test_this_machine_reports_its_free_memory() -> None:
    free = available_bytes()
    assert free is None or free > 0
