"""A prepared cache read as training batches (:class:`PreparedDataset`, :func:`window_indices`).

Integrity checks of the cache files are in ``test_cache.py``; these tests check what a
batch holds and how an epoch is cut into items.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import torch

from gnngarment.body.features import sliding_windows, velocity_windows
from gnngarment.data import CacheError, PreparedDataset, read_manifest
from gnngarment.data.cache import read_garment, read_topology, write_manifest, write_topology
from gnngarment.data.dataset import DEFAULT_FABRIC_DENSITY, window_indices
from gnngarment.geometry import edge_index_from_faces
from tests.synthetic_cache import build_synthetic_cache

FRAMES = 6
WINDOW = 3


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_synthetic_cache(tmp_path_factory.mktemp("cache"), frames=FRAMES)


@pytest.fixture(scope="module")
def dataset(cache: Path) -> PreparedDataset:
    return PreparedDataset(cache, "train", window=WINDOW)


def test_window_indices_end_at_their_frame_and_repeat_frame_zero() -> None:
    frames = np.array([0, 1, 4, 9])
    windows = window_indices(frames, 3)
    assert windows.shape == (4, 3)
    np.testing.assert_array_equal(windows[:, -1], frames)
    np.testing.assert_array_equal(windows, [[0, 0, 0], [0, 0, 1], [2, 3, 4], [7, 8, 9]])
    # The body layer's padding rule (what inference feeds the model), for every frame.
    np.testing.assert_array_equal(window_indices(np.arange(7), 4),
                                  sliding_windows(torch.arange(7), 4).numpy())


def test_length_and_names_are_the_splits(dataset: PreparedDataset, cache: Path) -> None:
    manifest = read_manifest(cache)
    assert len(dataset) == len(manifest["splits"]["train"]) == 6
    assert dataset.sequence_names == manifest["splits"]["train"]
    assert set(dataset.frame_counts.values()) == {FRAMES}
    assert len(PreparedDataset(cache, "test", window=WINDOW)) == 4


def test_windows_are_the_inference_windows_ending_at_the_predicted_frame(
        dataset: PreparedDataset) -> None:
    disk, tube = (next(n for n in dataset.sequence_names if n.startswith(kind))
                  for kind in ("disk", "tube"))
    frames = {disk: np.array([0, 1, 5]), tube: np.array([2, 3, 4])}
    batch = dataset.batch(list(frames.items()))
    subset = dataset.garment_of(disk).pair.body_distances.shape[0]
    assert batch.motion_windows.shape == (2, 3, WINDOW, 75)
    assert batch.velocity_windows.shape == (2, 3, WINDOW, 3 * subset)
    assert batch.joint_transforms.shape == (2, 3, 24, 4, 4)
    assert batch.num_frames == 3
    for p, (name, chosen) in enumerate(frames.items()):
        record = dataset.sequence(name)
        motion = torch.from_numpy(record.motion_features)
        # Exact copies of the cached arrays (torch.equal: no tolerance needed).
        assert torch.equal(batch.motion_windows[p, :, -1], motion[chosen])
        assert torch.equal(batch.motion_windows[p], sliding_windows(motion, WINDOW)[chosen])
        assert torch.equal(batch.velocity_windows[p], velocity_windows(
            torch.from_numpy(record.velocities), WINDOW)[chosen])
        assert torch.equal(batch.joint_transforms[p],
                           torch.from_numpy(record.joint_transforms[chosen]))
    # Frame 0's window is frame 0 repeated (no frames before the sequence starts).
    assert (batch.motion_windows[0, 0] == batch.motion_windows[0, 0, -1]).all()
    assert batch.sequences == [disk, tube]
    np.testing.assert_array_equal(batch.frames, [frames[disk], frames[tube]])
    assert batch.garment_types == ["disk", "tube"]


def test_every_item_holds_its_own_frame_mesh_and_body(dataset: PreparedDataset) -> None:
    names = [next(n for n in dataset.sequence_names if n.startswith(kind))
             for kind in ("tube_a_body1", "disk")]  # two garments, two sizes
    items = [(names[0], np.array([1, 4])), (names[1], np.array([0, 5]))]
    batch = dataset.batch(items)
    ptr = np.cumsum([0] + [dataset.garment_of(name).pair.rest_pos.shape[0]
                           for name, chosen in items for _ in chosen])
    assert batch.target.shape == batch.rest.shape == (ptr[-1], 3)
    assert batch.item.shape == batch.vertex_mass.shape == (ptr[-1],)
    assert batch.rest_inverse.shape == (len(batch.faces), 2, 2)
    assert batch.rest_area.shape == (len(batch.faces),)
    face_item = batch.item[batch.faces]
    assert (face_item == face_item[:, :1]).all()  # no triangle spans two items
    edge_item = batch.item[batch.edges]
    assert (edge_item[0] == edge_item[1]).all()
    k = 0
    for name, chosen in items:
        record, garment = dataset.sequence(name), dataset.garment_of(name)
        cached = read_garment(dataset.root, dataset.manifest["sequences"][name]["garment"])
        for frame in chosen:
            rows = slice(ptr[k], ptr[k + 1])
            assert (batch.item[rows] == k).all()
            np.testing.assert_array_equal(batch.target[rows].numpy(), record.positions[frame])
            np.testing.assert_array_equal(batch.rest[rows].numpy(), cached.rest_pos)
            faces = batch.faces[face_item[:, 0] == k] - ptr[k]
            np.testing.assert_array_equal(faces.numpy(), cached.faces)
            # Undirected edges of the item's mesh, each once (a < b).
            edges = batch.edges[:, edge_item[0] == k] - ptr[k]
            assert (edges[0] < edges[1]).all()
            expected = edge_index_from_faces(cached.faces, len(cached.rest_pos))
            assert ({tuple(e) for e in edges.T.tolist()}
                    == {tuple(e) for e in expected.T.tolist() if e[0] < e[1]})
            # Lumped masses add up to the fabric's areal density times the rest area.
            area = float(batch.rest_area[face_item[:, 0] == k].sum())
            assert float(batch.vertex_mass[rows].sum()) == pytest.approx(
                DEFAULT_FABRIC_DENSITY * area, rel=1e-5)
            points = batch.body_points[batch.body_item == k]
            np.testing.assert_array_equal(points.numpy(), record.body_points[frame])
            np.testing.assert_array_equal(batch.body_normals[batch.body_item == k].numpy(),
                                          record.body_normals[frame])
            k += 1
        assert torch.equal(garment.pair.rest_pos, torch.from_numpy(cached.rest_pos))
    assert int(batch.item.max()) + 1 == int(batch.body_item.max()) + 1 == k == 4


def test_frames_outside_a_sequence_are_rejected_naming_it(dataset: PreparedDataset) -> None:
    name = dataset.sequence_names[0]
    with pytest.raises(ValueError, match=f"sequence {name} has {FRAMES} frames, asked for 3..6"):
        dataset.batch([(name, np.array([3, FRAMES]))])
    with pytest.raises(ValueError, match=f"sequence {name} has {FRAMES} frames, asked for -1"):
        dataset.batch([(name, np.array([-1, 2]))])


def test_an_epoch_uses_every_frame_at_most_once(dataset: PreparedDataset) -> None:
    items = dataset.epoch_items(4, np.random.default_rng(3))
    # 6 frames in groups of 4: one item per sequence, the 2 leftover frames dropped.
    assert sorted(name for name, _ in items) == sorted(dataset.sequence_names)
    for _, frames in items:
        assert len(frames) == 4 and len(set(frames.tolist())) == 4
        assert (np.diff(frames) > 0).all() and frames.min() >= 0 and frames.max() < FRAMES
    pairs = dataset.epoch_items(2, np.random.default_rng(3))
    assert len(pairs) == 3 * len(dataset)  # 6 frames in groups of 2: nothing dropped
    for name in dataset.sequence_names:
        used = np.concatenate([frames for n, frames in pairs if n == name])
        np.testing.assert_array_equal(np.sort(used), np.arange(FRAMES))
    # Seeded: the same generator state gives the same epoch, another one another order.
    again = dataset.epoch_items(2, np.random.default_rng(3))
    assert [(n, f.tolist()) for n, f in again] == [(n, f.tolist()) for n, f in pairs]
    other = dataset.epoch_items(2, np.random.default_rng(4))
    assert [(n, f.tolist()) for n, f in other] != [(n, f.tolist()) for n, f in pairs]


def test_batches_cut_the_epoch_in_order(dataset: PreparedDataset) -> None:
    items = dataset.epoch_items(2, np.random.default_rng(5))
    groups = list(dataset.batches(4, 2, np.random.default_rng(5)))
    assert [len(group) for group in groups] == [4, 4, 4, 4, 2]  # 18 items
    flat = [(n, f.tolist()) for group in groups for n, f in group]
    assert flat == [(n, f.tolist()) for n, f in items]
    batch = dataset.batch(groups[-1])
    assert batch.motion_windows.shape[:2] == (2, 2)


def test_sequences_are_kept_in_a_bounded_cache(cache: Path) -> None:
    dataset = PreparedDataset(cache, "train", window=WINDOW, cache_sequences=1)
    first, second = dataset.sequence_names[:2]
    record = dataset.sequence(first)
    assert dataset.sequence(first) is record
    dataset.sequence(second)  # evicts the first
    again = dataset.sequence(first)
    assert again is not record
    np.testing.assert_array_equal(again.positions, record.positions)


def test_the_manifests_fabric_density_sets_the_masses(dataset: PreparedDataset, cache: Path,
                                                     tmp_path: Path) -> None:
    copy = tmp_path / "copy"
    shutil.copytree(cache, copy)
    manifest = read_manifest(copy)
    write_manifest(copy, manifest["splits"], manifest["sequences"],
                   extra={"fabric_density": 0.5})
    heavy = PreparedDataset(copy, "train", window=WINDOW)
    assert dataset.fabric_density == DEFAULT_FABRIC_DENSITY and heavy.fabric_density == 0.5
    name = dataset.sequence_names[0]
    np.testing.assert_allclose(heavy.garment_of(name).vertex_mass.numpy(),
                               dataset.garment_of(name).vertex_mass.numpy() * (0.5 / 0.2),
                               rtol=1e-6)


def test_a_hierarchy_of_another_garment_is_rejected_naming_the_topology(
        cache: Path, tmp_path: Path) -> None:
    copy = tmp_path / "copy"
    shutil.copytree(cache, copy)
    manifest = read_manifest(copy)
    disk = read_garment(copy, "disk_a_body0")
    tube = read_garment(copy, "tube_a_body0")
    assert disk.topology != tube.topology
    write_topology(copy, disk.topology, read_topology(copy, tube.topology))
    write_manifest(copy, manifest["splits"], manifest["sequences"])  # hashes match again
    dataset = PreparedDataset(copy, "train", window=WINDOW)
    name = next(n for n in dataset.sequence_names if n.startswith("disk_a_body0"))
    with pytest.raises(CacheError, match=f"topologies/{disk.topology}.npz: hierarchy has "
                       f"{len(tube.rest_pos)} vertices, garment disk_a_body0 has "
                       f"{len(disk.rest_pos)}"):
        dataset.batch([(name, np.array([0]))])
