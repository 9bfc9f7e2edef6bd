"""E^bs (:class:`BodyShapeEncoder`): one cue vector per joint from the distances ``D``."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gnngarment.model.body_shape_encoder import BodyShapeEncoder

VERTICES = 20


@pytest.fixture(scope="module")
def encoder() -> BodyShapeEncoder:
    torch.manual_seed(0)
    return BodyShapeEncoder(VERTICES, [32, 16])


def distances(bodies: int = 2, seed: int = 0) -> torch.Tensor:
    return torch.rand(bodies, VERTICES, 24, generator=torch.Generator().manual_seed(seed))


def close(actual: torch.Tensor, expected: torch.Tensor) -> None:
    np.testing.assert_allclose(actual.detach().numpy(), expected.detach().numpy(),
                               rtol=1e-6, atol=1e-7)


def test_one_cue_vector_per_joint(encoder: BodyShapeEncoder) -> None:
    cues = encoder(distances(3))
    assert cues.shape == (3, 24, 16)  # (G, N_b', S) -> (G, S, F)
    assert (cues >= 0).all() and (cues > 0).any()


def test_a_joints_cues_depend_on_its_own_column_only(encoder: BodyShapeEncoder) -> None:
    d = distances()
    cues = encoder(d)
    changed = d.clone()
    changed[:, :, 7] += 0.5
    moved = encoder(changed)
    others = [j for j in range(24) if j != 7]
    close(moved[:, others], cues[:, others])
    assert (moved[:, 7] - cues[:, 7]).abs().max() > 1e-4


def test_reordering_joints_reorders_the_cues(encoder: BodyShapeEncoder) -> None:
    # The same MLP for every joint: equal columns give equal cues, a permutation of the
    # joints permutes the cue vectors.
    d = distances()
    permutation = torch.randperm(24, generator=torch.Generator().manual_seed(1))
    close(encoder(d[:, :, permutation]), encoder(d)[:, permutation])
    d[:, :, 3] = d[:, :, 11]
    cues = encoder(d)
    close(cues[:, 3], cues[:, 11])


def test_bodies_do_not_mix(encoder: BodyShapeEncoder) -> None:
    d = distances(3)
    close(encoder(d)[1], encoder(d[1:2])[0])
    # and the vertex order of D matters: it is the fixed body subset, not a set
    assert (encoder(d.flip(1)) - encoder(d)).abs().max() > 1e-4
