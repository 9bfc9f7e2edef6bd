"""Inputs hashes: growing a config keeps the hash of every sequence it already planned;
what changes a simulation changes every hash."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from data_prep.inputs_hash import content_inputs, sequence_inputs_hash
from data_prep.plan import plan_dataset
from tests.data_prep.test_build import tiny_config


def test_more_motions_per_pair_keeps_every_built_sequence(tmp_path: Path) -> None:
    """Growing a dataset (more motions per pair, motion variants) plans every sequence it
    had with the same inputs hash, so a resumed build simulates only the new ones; each
    new variant moves at a tempo and amplitude of its own."""
    from data_prep.simulate import load_simulation_settings

    config = tiny_config(tmp_path)
    grown = replace(config, motions_per_pair=config.motions_per_pair + 1, motion_variants=2)
    settings = load_simulation_settings(config.simulation)
    before = {p.name: sequence_inputs_hash(content_inputs(config, settings), p)
              for p in plan_dataset(config)}
    after = {p.name: p for p in plan_dataset(grown)}
    hashes = {name: sequence_inputs_hash(content_inputs(grown, settings), p)
              for name, p in after.items()}
    assert all(hashes[name] == value for name, value in before.items())
    variants = [p.motion for p in after.values() if p.motion.speed != 1.0]
    assert len(variants) == len(after) - len(before) > 1
    assert len({(m.speed, m.amplitude, m.seed) for m in variants}) == len(variants)
    with pytest.raises(ValueError, match="motions_per_pair"):  # a motion twice per pair
        plan_dataset(replace(config, motions_per_pair=config.motions_per_pair + 1))
    # a change that alters what is simulated changes every hash
    slower = replace(config, fps=config.fps / 2)
    assert not any(sequence_inputs_hash(content_inputs(slower, settings), p) == before[p.name]
                   for p in plan_dataset(slower))


def test_extra_train_garments_keep_every_planned_sequence(tmp_path: Path) -> None:
    """More train designs (``extra_train_garments``) leave every sequence the config had
    — its validation and test sequences included — with the same plan and inputs hash,
    and add train sequences only, on designs of their own."""
    from data_prep.simulate import load_simulation_settings

    config = tiny_config(tmp_path)
    grown = replace(config, extra_train_garments=config.garments + 1)
    settings = load_simulation_settings(config.simulation)
    before = plan_dataset(config)
    after = plan_dataset(grown)
    assert after[:len(before)] == before
    hashes = [sequence_inputs_hash(content_inputs(grown, settings), p) for p in before]
    assert hashes == [sequence_inputs_hash(content_inputs(config, settings), p) for p in before]
    added = after[len(before):]
    assert added and {p.split for p in added} == {"train"}
    old_designs = {p.design.name for p in before}
    assert not {p.design.name for p in added} & old_designs
    assert len({p.design.seed for p in added}) == grown.extra_train_garments
    with pytest.raises(ValueError, match="extra_train_garments"):
        replace(config, extra_train_garments=-1)


def test_extra_held_out_garments_grow_their_split_only(tmp_path: Path) -> None:
    """More validation and test designs (``extra_val_garments``, ``extra_test_garments``)
    keep every sequence the config had, train extras included, and add sequences of
    their own split only, each on a body of that split, with a held-out motion."""
    from data_prep.simulate import load_simulation_settings

    config = replace(tiny_config(tmp_path), extra_train_garments=2)
    grown = replace(config, extra_val_garments=2, extra_test_garments=3)
    settings = load_simulation_settings(config.simulation)
    before = plan_dataset(config)
    after = plan_dataset(grown)
    assert after[:len(before)] == before
    assert ([sequence_inputs_hash(content_inputs(grown, settings), p) for p in before]
            == [sequence_inputs_hash(content_inputs(config, settings), p) for p in before])
    added = after[len(before):]
    assert {p.split for p in added} == {"val", "test"}
    assert all(p.body.split == p.split and p.motion.split == p.split for p in added)
    designs = {split: {p.design.name for p in added if p.split == split}
               for split in ("val", "test")}
    assert (len(designs["val"]), len(designs["test"])) == (2, 3)
    assert not (designs["val"] | designs["test"]) & {p.design.name for p in before}
    # a split's extra designs do not depend on another split's count
    fewer_test = plan_dataset(replace(config, extra_val_garments=2, extra_test_garments=1))
    assert ([p.design.seed for p in fewer_test if p.split == "val" and p not in before]
            == [p.design.seed for p in added if p.split == "val"])
    with pytest.raises(ValueError, match="extra_test_garments"):
        replace(config, extra_test_garments=-1)
