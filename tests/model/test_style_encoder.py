"""E^gs (:class:`StyleEncoder`): style cues from the Nyström descriptor."""

from __future__ import annotations

import numpy as np
import torch

from gnngarment.geometry import GarmentPreparationConfig, prepare_garment
from gnngarment.model.style_encoder import StyleEncoder
from tests.meshes import interleave, random_disk, tube

LANDMARKS = 16


def encoder(seed: int = 0) -> StyleEncoder:
    torch.manual_seed(seed)
    return StyleEncoder(LANDMARKS, [32, 16])


def descriptor(pos: np.ndarray, faces: np.ndarray) -> torch.Tensor:
    prepared = prepare_garment(pos, faces, GarmentPreparationConfig(levels=1,
                                                                    landmarks=LANDMARKS))
    return torch.tensor(prepared.descriptor, dtype=torch.float32)


def test_one_cue_vector_per_garment_of_the_last_width() -> None:
    cues = encoder()(torch.rand(5, LANDMARKS))
    assert cues.shape == (5, 16)
    assert (cues >= 0).all()  # ReLU after the last layer, as every encoder
    assert (cues > 0).any()


def test_garments_of_any_size_get_cues_and_do_not_mix() -> None:
    # The descriptor has `landmarks` values whatever the vertex count, so garments of
    # different sizes share one batch; each garment's cues depend on its own row only.
    disk, skirt = descriptor(*random_disk(90, 4)), descriptor(*tube(6, 10))
    assert disk.shape == skirt.shape == (LANDMARKS,)
    style = encoder()
    together = style(torch.stack([disk, skirt]))
    np.testing.assert_allclose(together[0].detach().numpy(),
                               style(disk[None])[0].detach().numpy(), rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(together[1].detach().numpy(),
                               style(skirt[None])[0].detach().numpy(), rtol=1e-6, atol=1e-7)
    assert (together[0] - together[1]).abs().max() > 1e-3  # different garments, different cues


def test_relabelling_the_vertices_keeps_the_style() -> None:
    pos, faces = random_disk(90, 4)
    style = encoder()
    before = style(descriptor(pos, faces)[None])
    after = style(descriptor(*interleave(pos, faces, seed=2))[None])
    np.testing.assert_allclose(after.detach().numpy(), before.detach().numpy(),
                               rtol=1e-5, atol=1e-6)


def test_the_cues_follow_the_descriptor() -> None:
    style = encoder()
    base = torch.rand(1, LANDMARKS)
    changed = base.clone()
    changed[0, -1] += 1.0  # even the smallest eigenvalue's slot is read
    assert (style(changed) - style(base)).abs().max() > 1e-4
    # Seeded construction gives the same encoder.
    np.testing.assert_array_equal(encoder(3)(base).detach().numpy(),
                                  encoder(3)(base).detach().numpy())
