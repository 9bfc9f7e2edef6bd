"""`animate` gives a penetration-free garment by default and keeps the network's own
output beside it."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gnngarment.body.skinning import skin
from gnngarment.data.body_inputs import BodyMotionInputs, BodyShapeInputs
from gnngarment.geometry.body_collisions import CollisionSettings
from gnngarment.geometry.signed_distance import signed_distance
from gnngarment.inference.animate import animate
from gnngarment.model import GarmentDeformer
from tests.inference.animations import REST_JOINTS, joint_transforms, rest_body, rest_garment
from tests.model.pairs import tiny_config

EPSILON = CollisionSettings().epsilon
FRAMES = 4


@pytest.fixture(scope="module")
def scene() -> dict:
    """A tiny model, a cylinder "body" (radius 0.14) posed rigidly per joint, and a tube
    garment of radius 0.13: inside the rest body."""
    torch.manual_seed(0)
    model = GarmentDeformer(tiny_config())
    config = model.config
    body_pos, body_faces = rest_body()
    nearest = np.linalg.norm(body_pos[:, None] - REST_JOINTS[None], axis=-1).argmin(axis=1)
    body_weights = np.eye(24, dtype=np.float32)[nearest]
    rng = np.random.default_rng(0)
    shape = BodyShapeInputs(
        joints=REST_JOINTS.astype(np.float32),
        distances=rng.random((config.body_vertices, 24)).astype(np.float32),
        subset=np.arange(config.body_vertices), rest_vertices=body_pos, faces=body_faces,
        skinning_weights=body_weights)
    transforms = joint_transforms(FRAMES, amplitude=0.3)
    posed_body = skin(torch.tensor(body_pos, dtype=torch.float32), None,
                      torch.tensor(body_weights), torch.tensor(transforms)).numpy()
    frames = BodyMotionInputs(
        motion_features=rng.normal(scale=0.1, size=(FRAMES, 75)).astype(np.float32),
        velocities=rng.normal(scale=0.1, size=(FRAMES, config.body_vertices, 3)
                              ).astype(np.float32),
        joint_transforms=transforms, vertices=posed_body, fps=30.0)
    pos, faces = rest_garment()
    pos[:, :2] *= 0.13 / 0.22
    return {"model": model, "pos": pos, "faces": faces, "body": shape, "frames": frames}


def test_output_and_rest_garment_are_moved_out_of_the_body(scene) -> None:
    body, frames = scene["body"], scene["frames"]
    rest_depth = signed_distance(scene["pos"], body.rest_vertices, body.faces)
    assert (rest_depth < 0).mean() > 0.9  # the given garment lies inside the rest body
    animation = animate(scene["model"], scene["pos"], scene["faces"], body, frames)
    np.testing.assert_array_equal(animation.raw_rest_pos, scene["pos"].astype(np.float32))
    assert signed_distance(animation.rest_pos, body.rest_vertices,
                           body.faces).min() >= EPSILON * 0.999
    assert animation.rest_collisions.close[0] == (rest_depth < EPSILON).sum()
    assert animation.raw_posed.shape == animation.posed.shape == (FRAMES, len(scene["pos"]), 3)
    raw_inside = 0
    for t in range(FRAMES):
        after = signed_distance(animation.posed[t], frames.vertices[t], body.faces)
        assert after.min() >= EPSILON * 0.999, t
        raw_inside += (signed_distance(animation.raw_posed[t], frames.vertices[t],
                                       body.faces) < 0).sum()
    # The network started from the resolved rest garment, yet its output still
    # touches the moving body somewhere: that is what the per-frame step removes.
    assert raw_inside > 0 and animation.collisions.close.sum() > 0
    assert animation.seconds["collisions"] > 0


def test_resolution_can_be_turned_off(scene) -> None:
    animation = animate(scene["model"], scene["pos"], scene["faces"], scene["body"],
                        scene["frames"], resolve_collisions=False)
    assert animation.posed is animation.raw_posed
    np.testing.assert_array_equal(animation.rest_pos, scene["pos"].astype(np.float32))
    assert animation.collisions is None and animation.rest_collisions is None
    # A larger ε moves vertices farther.
    wide = animate(scene["model"], scene["pos"], scene["faces"], scene["body"],
                   scene["frames"], collisions=CollisionSettings(epsilon=0.01))
    assert signed_distance(wide.rest_pos, scene["body"].rest_vertices,
                           scene["body"].faces).min() >= 0.01 * 0.999


def test_triangle_soup_is_animated_as_the_welded_mesh(scene) -> None:
    """An STL-style garment (every triangle its own three vertices) gives exactly the
    animation of the welded mesh, in the file's vertex order, copies moving as one."""
    body, frames = scene["body"], scene["frames"]
    pos, faces = scene["pos"], scene["faces"]
    soup_pos = pos[faces.reshape(-1)]
    soup_faces = np.arange(len(soup_pos)).reshape(-1, 3)
    welded = animate(scene["model"], pos, faces, body, frames)
    soup = animate(scene["model"], soup_pos, soup_faces, body, frames)
    assert soup.welded == len(soup_pos) - len(pos)
    assert welded.welded == 0
    np.testing.assert_array_equal(soup.faces, soup_faces)
    np.testing.assert_allclose(soup.posed, welded.posed[:, faces.reshape(-1)], atol=1e-6)
    np.testing.assert_allclose(soup.weights, welded.weights[:, faces.reshape(-1)], atol=1e-6)


def test_frames_in_chunks_of_any_size_give_the_same_animation(scene) -> None:
    """A large garment runs fewer frames per pass (bounded memory): the frames are
    independent given the context, so the chunking changes nothing beyond float noise."""
    from gnngarment.inference.animate import MAX_FRAMES_PER_CHUNK, frames_per_chunk

    whole = animate(scene["model"], scene["pos"], scene["faces"], scene["body"],
                    scene["frames"], resolve_collisions=False, chunk=FRAMES)
    single = animate(scene["model"], scene["pos"], scene["faces"], scene["body"],
                     scene["frames"], resolve_collisions=False, chunk=1)
    np.testing.assert_allclose(single.posed, whole.posed, atol=1e-6)
    np.testing.assert_allclose(single.weights, whole.weights, atol=1e-6)
    assert frames_per_chunk(5_000) == MAX_FRAMES_PER_CHUNK == frames_per_chunk(10)
    assert frames_per_chunk(20_000) == 4 and frames_per_chunk(300_000) == 1
