"""Outfit layers: order at rest, resolution out of the garment beneath, parts of a file."""

import numpy as np
import pytest

from gnngarment.geometry.garment_layers import (
    LayerOrderError,
    LayerSettings,
    connected_parts,
    layer_order,
    layer_penetration,
    part_mesh,
    resolve_layer_collisions,
)


def cylinder(radius, z0=0.0, z1=0.3, around=48, rows=16):
    """An open tube around the Z axis, faces wound with normals pointing outward."""
    angle = np.linspace(0, 2 * np.pi, around, endpoint=False)
    z = np.linspace(z0, z1, rows)
    pos = np.stack([np.repeat(radius * np.cos(angle)[None], rows, 0),
                    np.repeat(radius * np.sin(angle)[None], rows, 0),
                    np.repeat(z[:, None], around, 1)], -1).reshape(-1, 3)
    faces = []
    for r in range(rows - 1):
        for a in range(around):
            i, j = r * around + a, r * around + (a + 1) % around
            faces += [[i, j, j + around], [i, j + around, i + around]]
    return pos, np.asarray(faces)


def test_the_outer_tube_is_found_outside_whatever_the_given_order():
    inner, outer = cylinder(0.10), cylinder(0.115)
    order, relations = layer_order([outer, inner], ["coat", "shirt"])
    assert order == [1, 0]
    assert relations[0].outer == 0 and relations[0].agreement == 1.0
    assert layer_order([inner, outer], ["shirt", "coat"])[0] == [0, 1]


def test_tubes_that_cross_are_refused_not_guessed():
    inner = cylinder(0.10)
    pos, faces = cylinder(0.10)
    pos = pos.copy()
    pos[:, :2] *= np.where(pos[:, 2:] > 0.15, 1.1, 0.9)   # outside above, inside below
    with pytest.raises(LayerOrderError, match="cross"):
        layer_order([inner, (pos, faces)], ["a", "b"])


def test_an_outer_tube_through_the_inner_one_ends_outside_by_the_clearance():
    inner_pos, inner_faces = cylinder(0.10, -0.1, 0.4)
    outer_pos, outer_faces = cylinder(0.095)
    settings = LayerSettings()
    frames = np.stack([outer_pos, outer_pos * [1.02, 1.02, 1]])
    inner = np.stack([inner_pos, inner_pos])
    assert layer_penetration(frames, inner, inner_faces).min() == 1.0
    resolved, stats = resolve_layer_collisions(frames, outer_faces, [(inner, inner_faces)],
                                               settings)
    assert (stats.through > 0).all() and (stats.remaining == 0).all()
    radius = np.linalg.norm(resolved[..., :2], axis=-1)
    # (the tube is a 48-gon: its faces lie up to 0.10 (1 - cos(pi/48)) inside the circle)
    assert radius.min() >= 0.10 * np.cos(np.pi / 48) + settings.clearance * 0.99
    # No more than it needs: the deepest vertex moved by its depth plus the clearance.
    assert stats.max_push[0] == pytest.approx(0.005 + settings.clearance, abs=1e-3)
    assert layer_penetration(resolved, inner, inner_faces).max() == 0.0


def test_garments_apart_are_returned_bit_for_bit():
    inner_pos, inner_faces = cylinder(0.10)
    outer_pos, outer_faces = cylinder(0.2, 0.5, 0.8)
    outer = outer_pos.astype(np.float32)
    resolved, stats = resolve_layer_collisions(outer, outer_faces, [(inner_pos, inner_faces)])
    assert resolved.dtype == np.float32 and np.array_equal(resolved, outer)
    assert stats.moved.sum() == 0


def test_a_file_of_two_garments_splits_into_two_parts():
    top, bottom = cylinder(0.1, 0.3, 0.6), cylinder(0.1, 0.0, 0.25)
    pos = np.concatenate([top[0], bottom[0]])
    faces = np.concatenate([top[1], bottom[1] + len(top[0])])
    parts = connected_parts(faces, len(pos))
    assert [len(part) for part in parts] == [len(top[0]), len(bottom[0])]
    part_pos, part_faces = part_mesh(pos, faces, parts[1])
    assert np.array_equal(part_pos, bottom[0]) and np.array_equal(part_faces, bottom[1])


def test_the_layer_config_mirrors_the_dataclass():
    from dataclasses import asdict

    from gnngarment.config import read_yaml
    from gnngarment.paths import default_config

    assert read_yaml(default_config("layers.yaml")) == asdict(LayerSettings())
