"""Reading a prepared cache as model inputs and training batches."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import torch

from gnngarment.body.skeleton import NUM_JOINTS
from gnngarment.data.cache import (
    CacheError,
    SequenceRecord,
    check_file_hash,
    check_file_sizes,
    read_body,
    read_garment,
    read_manifest,
    read_sequence,
    read_topology,
)
from gnngarment.data.pair import GarmentBodyPair
from gnngarment.data.vertex_features import garment_vertex_features
from gnngarment.geometry.triangle_frames import rest_triangle_frames, vertex_masses

#: Areal density (kg/m²) used for vertex masses when the cache does not record one:
#: a mid-weight cotton.
DEFAULT_FABRIC_DENSITY = 0.2


@dataclass
class TrainingBatch:
    """``P`` sequences × ``B`` frames, laid out as :class:`DeformerOutput` items
    (item ``k = p·B + b``).

    Attributes:
        pairs: ``P`` garment–body pairs (for :meth:`GarmentDeformer.encode`).
        motion_windows ``(P, B, m, 75)``, velocity_windows ``(P, B, m, 3 N_b')``,
        joint_transforms ``(P, B, 24, 4, 4)``: the per-frame model inputs.
        target: ``(V, 3)`` ground-truth garment vertices.
        rest: ``(V, 3)`` rest garment vertices of every item.
        faces: ``(F_V, 3)`` triangles of every item (offset into ``V``).
        edges: ``(2, E_V)`` undirected edges of every item (each once).
        rest_inverse ``(F_V, 2, 2)``, rest_area ``(F_V,)``: rest triangle frames.
        vertex_mass: ``(V,)`` lumped vertex masses (kg) at the cache's fabric density.
        item: ``(V,)`` item of every vertex.
        body_points, body_normals: ``(M_V, 3)`` posed-body collision samples;
        body_item: ``(M_V,)`` their item.
        garment_types: ``P`` type names; sequences: ``P`` sequence names;
        frames: ``(P, B)`` frame indices.
        sequence_transforms: ``P`` tensors ``(T_p, 24, 4, 4)``, every frame of each
            sequence (the oscillators' drive needs the history before the frames).
        fps: frames per second of the sequences (one value for the batch).
    """

    pairs: list[GarmentBodyPair]
    motion_windows: torch.Tensor
    velocity_windows: torch.Tensor
    joint_transforms: torch.Tensor
    target: torch.Tensor
    rest: torch.Tensor
    faces: torch.Tensor
    edges: torch.Tensor
    rest_inverse: torch.Tensor
    rest_area: torch.Tensor
    vertex_mass: torch.Tensor
    item: torch.Tensor
    body_points: torch.Tensor
    body_normals: torch.Tensor
    body_item: torch.Tensor
    garment_types: list[str]
    sequences: list[str]
    frames: np.ndarray
    sequence_transforms: list[torch.Tensor] | None = None
    fps: float = 30.0

    @property
    def num_frames(self) -> int:
        return int(self.motion_windows.shape[1])


@dataclass
class _GarmentData:
    pair: GarmentBodyPair
    faces: torch.Tensor
    edges: torch.Tensor
    rest_inverse: torch.Tensor
    rest_area: torch.Tensor
    vertex_mass: torch.Tensor
    garment_type: str


def window_indices(frames: np.ndarray, window: int) -> np.ndarray:
    """``(len(frames), window)`` indices of the last ``window`` frames before each frame,
    oldest first; indices before 0 repeat frame 0 (the padding rule of the body layer)."""
    return np.clip(np.asarray(frames)[:, None] + np.arange(-window + 1, 1)[None, :], 0, None)


def _one_rate(rates: set[float], names: list[str]) -> float:
    if len(rates) != 1:
        raise ValueError(f"sequences {names} have different frame rates {sorted(rates)}; "
                         "a batch needs one")
    return rates.pop()


class PreparedDataset:
    """One split of a prepared cache.

    The cache is checked against its manifest: every listed file's size when the
    dataset is made (a ``stat`` each), and a file's sha256 the first time this dataset
    reads it (once per file, so its cost is one extra read of what is read anyway).

    Args:
        root: cache folder (holds ``manifest.json``).
        split: ``train``, ``val`` or ``test`` (or any split the manifest lists).
        window: ``m`` frames of motion history (the model's ``window``).
        cache_sequences: sequences kept in memory (LRU).
    """

    def __init__(self, root: str | Path, split: str, window: int, cache_sequences: int = 256):
        self.root = Path(root)
        self.manifest = read_manifest(self.root)
        splits = self.manifest.get("splits", {})
        if split not in splits:
            raise CacheError(f"{self.root / 'manifest.json'}: no split '{split}' "
                             f"(has {sorted(splits)})")
        self.split = split
        self.window = window
        self.fabric_density = float(self.manifest.get("fabric_density", DEFAULT_FABRIC_DENSITY))
        self.sequence_names: list[str] = list(splits[split])
        self.frame_counts: dict[str, int] = {
            name: int(self.manifest["sequences"][name]["frames"]) for name in self.sequence_names}
        check_file_sizes(self.root, self.manifest)
        self._verified: set[str] = set()
        self._sequence = lru_cache(maxsize=cache_sequences)(self._read_sequence)
        self._garment = lru_cache(maxsize=None)(self._read_garment)

    def __len__(self) -> int:
        return len(self.sequence_names)

    def _verify(self, relative: str) -> None:
        """Check a file's sha256 against the manifest, the first time it is read."""
        if relative not in self._verified:
            check_file_hash(self.root, self.manifest, relative)
            self._verified.add(relative)

    def _read_sequence(self, name: str) -> SequenceRecord:
        self._verify(f"sequences/{name}.npz")
        return read_sequence(self.root, name)

    def _read_garment(self, garment: str, body: str) -> _GarmentData:
        self._verify(f"garments/{garment}.npz")
        self._verify(f"bodies/{body}.npz")
        record = read_garment(self.root, garment)
        body_record = read_body(self.root, body)
        self._verify(f"topologies/{record.topology}.npz")
        hierarchy = read_topology(self.root, record.topology)
        if hierarchy.num_vertices != len(record.rest_pos):
            raise CacheError(f"{self.root}/topologies/{record.topology}.npz: hierarchy has "
                             f"{hierarchy.num_vertices} vertices, garment {garment} has "
                             f"{len(record.rest_pos)}")
        features = garment_vertex_features(record.rest_pos, record.faces, body_record.joints)
        faces = torch.from_numpy(record.faces.astype(np.int64))
        edge_index = hierarchy.edge_index
        edges = torch.from_numpy(edge_index[:, edge_index[0] < edge_index[1]].astype(np.int64))
        rest_inverse, rest_area = rest_triangle_frames(record.rest_pos, record.faces)
        # Both cache builders store the transferred body weights and joint distances; a
        # cache without them cannot recompute them (it keeps no body mesh): the pair then
        # has none, and a model with the ``body`` weight prior (or a reach) rejects it by
        # name.
        count = len(record.rest_pos)
        for name in ("body_weights", "joint_distances"):
            values = getattr(record, name)
            if values is not None and tuple(values.shape) != (count, NUM_JOINTS):
                raise CacheError(f"{self.root}/garments/{garment}.npz: {name} has shape "
                                 f"{tuple(values.shape)}, expected ({count}, {NUM_JOINTS})")
        pair = GarmentBodyPair.from_arrays(record.rest_pos, features, hierarchy,
                                           record.descriptor, body_record.distances,
                                           record.body_weights, record.joint_distances)
        mass = vertex_masses(record.rest_pos, record.faces, self.fabric_density)
        return _GarmentData(pair=pair, faces=faces, edges=edges,
                            rest_inverse=torch.from_numpy(rest_inverse.astype(np.float32)),
                            rest_area=torch.from_numpy(rest_area.astype(np.float32)),
                            vertex_mass=torch.from_numpy(mass.astype(np.float32)),
                            garment_type=record.garment_type)

    def sequence(self, name: str) -> SequenceRecord:
        return self._sequence(name)

    def garment_of(self, sequence: str) -> _GarmentData:
        info = self.manifest["sequences"][sequence]
        return self._garment(info["garment"], info["body"])

    def batch(self, items: Sequence[tuple[str, np.ndarray]]) -> TrainingBatch:
        """Assemble a batch from ``(sequence name, frame indices)`` items; every item
        must have the same number of frames ``B``."""
        frames_per_item = {len(frames) for _, frames in items}
        if len(frames_per_item) != 1:
            raise ValueError(f"every item needs the same number of frames, got "
                             f"{sorted(frames_per_item)}")
        pairs, motion, velocity, transforms = [], [], [], []
        target, rest, faces, edges, inverse, area, mass, item = [], [], [], [], [], [], [], []
        body_points, body_normals, body_item, types = [], [], [], []
        whole, rates = [], set()
        offset, k = 0, 0
        for name, frames in items:
            record = self.sequence(name)
            garment = self.garment_of(name)
            frames = np.asarray(frames, dtype=np.int64)
            if frames.min() < 0 or frames.max() >= record.num_frames:
                raise ValueError(f"sequence {name} has {record.num_frames} frames, asked for "
                                 f"{frames.min()}..{frames.max()}")
            windows = window_indices(frames, self.window)
            pairs.append(garment.pair)
            types.append(garment.garment_type)
            motion.append(torch.from_numpy(record.motion_features[windows]))
            velocity.append(torch.from_numpy(
                record.velocities[windows].reshape(len(frames), self.window, -1)))
            transforms.append(torch.from_numpy(record.joint_transforms[frames]))
            whole.append(torch.from_numpy(record.joint_transforms))
            rates.add(float(record.fps))
            n = garment.pair.rest_pos.shape[0]
            for frame in frames:
                target.append(torch.from_numpy(record.positions[frame]))
                rest.append(garment.pair.rest_pos)
                faces.append(garment.faces + offset)
                edges.append(garment.edges + offset)
                inverse.append(garment.rest_inverse)
                area.append(garment.rest_area)
                mass.append(garment.vertex_mass)
                item.append(torch.full((n,), k, dtype=torch.long))
                points = torch.from_numpy(record.body_points[frame])
                body_points.append(points)
                body_normals.append(torch.from_numpy(record.body_normals[frame]))
                body_item.append(torch.full((len(points),), k, dtype=torch.long))
                offset += n
                k += 1
        return TrainingBatch(
            pairs=pairs, motion_windows=torch.stack(motion), velocity_windows=torch.stack(velocity),
            joint_transforms=torch.stack(transforms), target=torch.cat(target),
            rest=torch.cat(rest), faces=torch.cat(faces), edges=torch.cat(edges, dim=1),
            rest_inverse=torch.cat(inverse), rest_area=torch.cat(area),
            vertex_mass=torch.cat(mass), item=torch.cat(item),
            body_points=torch.cat(body_points), body_normals=torch.cat(body_normals),
            body_item=torch.cat(body_item), garment_types=types,
            sequences=[name for name, _ in items],
            frames=np.stack([np.asarray(f) for _, f in items]),
            sequence_transforms=whole, fps=_one_rate(rates, [name for name, _ in items]))

    def epoch_items(self, frames_per_item: int, rng: np.random.Generator
                    ) -> list[tuple[str, np.ndarray]]:
        """Every frame of every sequence once, in random groups of ``frames_per_item``
        frames of one sequence (a sequence's leftover frames are dropped this epoch)."""
        items = []
        for name in self.sequence_names:
            order = rng.permutation(self.frame_counts[name])
            for start in range(0, len(order) - frames_per_item + 1, frames_per_item):
                items.append((name, np.sort(order[start:start + frames_per_item])))
        order = rng.permutation(len(items))
        return [items[i] for i in order]

    def batches(self, pairs_per_batch: int, frames_per_item: int, rng: np.random.Generator
                ) -> Iterator[list[tuple[str, np.ndarray]]]:
        """Groups of ``pairs_per_batch`` items for one epoch (pass each to :meth:`batch`)."""
        items = self.epoch_items(frames_per_item, rng)
        for start in range(0, len(items), pairs_per_batch):
            yield items[start:start + pairs_per_batch]
