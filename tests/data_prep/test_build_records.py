"""Build records: a recorded failure is tied to its inputs, a truncated or damaged
sequence is not counted as built, and losses are counted by reason."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from data_prep.build_records import known_failure, left_out, losses_by_reason, sequence_done
from data_prep.plan import plan_dataset
from tests.data_prep.test_build import tiny_config


def test_recorded_failure_is_tied_to_its_inputs(tmp_path: Path) -> None:
    left_out(tmp_path, "skirt000_body00_walk00", "hash-a", "max edge stretch", time.perf_counter())
    assert known_failure(tmp_path, "skirt000_body00_walk00", "hash-a") == "max edge stretch"
    assert known_failure(tmp_path, "skirt000_body00_walk00", "hash-b") is None  # inputs changed
    assert known_failure(tmp_path, "other", "hash-a") is None
    (tmp_path / "sequences" / "truncated.failed").write_text('{"inputs_ha')
    assert known_failure(tmp_path, "truncated", "hash-a") is None


def test_a_truncated_sequence_is_rebuilt_not_counted_as_built(tmp_path: Path) -> None:
    from gnngarment.io.npz import save_npz_atomic

    path = tmp_path / "sequences" / "skirt000_body00_walk00.npz"
    save_npz_atomic(path, {"positions": np.zeros((4, 50, 3), np.float32)})
    (path.parent / "skirt000_body00_walk00.hash").write_text("hash-a")
    assert sequence_done(tmp_path, "skirt000_body00_walk00", "hash-a")
    assert not sequence_done(tmp_path, "skirt000_body00_walk00", "hash-b")  # inputs changed
    whole = path.read_bytes()
    path.write_bytes(whole[:len(whole) // 2])                     # cut short
    assert not sequence_done(tmp_path, "skirt000_body00_walk00", "hash-a")
    damaged = bytearray(whole)
    damaged[len(whole) // 2] ^= 0xFF                              # one byte of its data
    path.write_bytes(bytes(damaged))
    assert not sequence_done(tmp_path, "skirt000_body00_walk00", "hash-a")


def test_losses_are_counted_by_reason(tmp_path: Path) -> None:
    plans = plan_dataset(tiny_config(tmp_path))
    garment = plans[0].garment
    on_that_garment = sum(p.garment == garment for p in plans)
    others = [p for p in plans if p.garment != garment]
    counts = losses_by_reason(
        {others[0].name: "garment slid off the body: mean distance 0.20 m > 0.15 m at frame 3",
         others[1].name: "simulation failed after 2 attempt(s): attempt 1: frame 4: max edge "
                         "stretch 1.700 > 1.500"},
        {garment: "drape: garment fell down the body: mean drop 0.30 m > 0.15 m"}, plans)
    assert counts == {"planned": len(plans), "lost": on_that_garment + 2,
                      "drape failed": on_that_garment, "left the body": 1, "edge stretch": 1}
