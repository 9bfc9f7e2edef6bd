"""The prepared cache: manifest, integrity checks, batches of mixed garments."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gnngarment.data import CacheError, PreparedDataset, read_manifest, verify_cache
from tests.synthetic_cache import build_synthetic_cache


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_synthetic_cache(tmp_path_factory.mktemp("cache"), frames=5)


def test_manifest_lists_splits_and_every_file(cache: Path) -> None:
    manifest = read_manifest(cache)
    assert set(manifest["splits"]) == {"train", "val", "test"}
    assert all(name.startswith(("topologies/", "garments/", "bodies/", "sequences/"))
               for name in manifest["files"])
    assert verify_cache(cache) == []


def test_batch_of_mixed_garments_is_laid_out_item_by_item(cache: Path) -> None:
    dataset = PreparedDataset(cache, "train", window=3)
    names = dataset.sequence_names
    disk = next(n for n in names if n.startswith("disk"))
    tube = next(n for n in names if n.startswith("tube"))
    batch = dataset.batch([(disk, np.array([0, 2])), (tube, np.array([1, 4]))])
    n_disk, n_tube = (dataset.garment_of(n).pair.rest_pos.shape[0] for n in (disk, tube))
    assert batch.target.shape == (2 * (n_disk + n_tube), 3)
    assert batch.item.tolist() == [0] * n_disk + [1] * n_disk + [2] * n_tube + [3] * n_tube
    assert batch.motion_windows.shape == (2, 2, 3, 75)
    assert batch.faces.max() < batch.target.shape[0]
    record = dataset.sequence(tube)
    np.testing.assert_allclose(batch.target[2 * n_disk + n_tube:].numpy(), record.positions[4])
    with pytest.raises(ValueError, match="same number of frames"):
        dataset.batch([(disk, np.array([0])), (tube, np.array([1, 2]))])


def test_truncated_and_missing_files_are_named(cache: Path, tmp_path: Path) -> None:
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(cache, copy)
    sequence = sorted((copy / "sequences").glob("*.npz"))[0]
    sequence.write_bytes(sequence.read_bytes()[:200])
    problems = verify_cache(copy)
    assert len(problems) == 1 and sequence.name in problems[0]
    # Caught when the dataset is made (its size differs from the manifest's), by name.
    with pytest.raises(CacheError, match=f"{sequence.name}: 200 bytes, the manifest says"):
        PreparedDataset(copy, "train", window=2)
    sequence.unlink()
    with pytest.raises(CacheError, match=f"{sequence.name}: listed in the manifest but missing"):
        PreparedDataset(copy, "train", window=2)
    with pytest.raises(CacheError, match="no split 'holdout'"):
        PreparedDataset(copy, "holdout", window=2)
    with pytest.raises(CacheError, match="no prepared cache"):
        PreparedDataset(tmp_path / "empty", "train", window=2)


def test_a_sequence_swapped_for_another_is_caught_naming_it(cache: Path,
                                                            tmp_path: Path) -> None:
    import json
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(cache, copy)
    manifest = read_manifest(copy)
    name, other = (n for n in manifest["splits"]["train"] if n.startswith("tube_a_body0"))
    first, second = (copy / "sequences" / f"{n}.npz" for n in (name, other))
    assert first.stat().st_size == second.stat().st_size  # the size check cannot see it
    shutil.copyfile(second, first)
    dataset = PreparedDataset(copy, "train", window=2)
    dataset.sequence(other)
    with pytest.raises(CacheError, match=f"{first.name}: content differs from the manifest"):
        dataset.sequence(name)
    # A cache written before sizes were recorded is still read, and still hash-checked.
    del manifest["sizes"]
    (copy / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(CacheError, match=f"{first.name}: content differs"):
        PreparedDataset(copy, "train", window=2).batch([(name, np.array([0]))])


def test_pairs_carry_the_cached_body_weights(cache: Path, tmp_path: Path) -> None:
    import shutil
    from dataclasses import replace

    from gnngarment.data.cache import read_garment, write_garment, write_manifest

    dataset = PreparedDataset(cache, "train", window=2)
    name = dataset.sequence_names[0]
    garment = dataset.manifest["sequences"][name]["garment"]
    record = read_garment(cache, garment)
    np.testing.assert_array_equal(dataset.garment_of(name).pair.body_weights.numpy(),
                                  record.body_weights)

    copy = tmp_path / "copy"
    shutil.copytree(cache, copy)
    manifest = read_manifest(copy)

    def rewrite(garment_record) -> None:  # and commit it: the manifest lists its hash
        write_garment(copy, garment_record)
        write_manifest(copy, manifest["splits"], manifest["sequences"])

    rewrite(replace(record, body_weights=None))   # a cache from before them
    assert PreparedDataset(copy, "train", window=2).garment_of(name).pair.body_weights is None
    rewrite(replace(record, body_weights=record.body_weights[:-1]))
    with pytest.raises(CacheError, match="body_weights has shape"):
        PreparedDataset(copy, "train", window=2).garment_of(name)
    rewrite(replace(record, joint_distances=record.joint_distances[:, :23]))
    with pytest.raises(CacheError, match=rf"{garment}\.npz: joint_distances has shape"):
        PreparedDataset(copy, "train", window=2).garment_of(name)
