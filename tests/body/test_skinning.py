import pytest
import torch

from gnngarment.body.rotations import axis_angle_to_matrix
from gnngarment.body.skeleton import forward_kinematics
from gnngarment.body.skinning import skin


def _random_transforms(batch, seed=0, dtype=torch.float64):
    g = torch.Generator().manual_seed(seed)
    rest = torch.randn(24, 3, generator=g, dtype=dtype)
    transforms, _ = forward_kinematics(
        0.5 * torch.randn(batch, 24, 3, generator=g, dtype=dtype),
        rest,
        torch.randn(batch, 3, generator=g, dtype=dtype),
    )
    return transforms


def test_identity_gives_rest():
    rest = torch.randn(2, 50, 3)
    weights = torch.softmax(torch.randn(2, 50, 24), -1)
    out = skin(rest, None, weights, torch.eye(4).expand(2, 24, 4, 4))
    assert torch.allclose(out, rest, atol=1e-6)
    blend = 0.01 * torch.randn(2, 50, 3)
    assert torch.allclose(
        skin(rest, blend, weights, torch.eye(4).expand(2, 24, 4, 4)), rest + blend, atol=1e-6
    )


def test_single_joint_is_rigid():
    transforms = _random_transforms(3)
    rest = torch.randn(3, 40, 3, dtype=torch.float64)
    weights = torch.zeros(3, 40, 24, dtype=torch.float64)
    weights[..., 7] = 1.0
    out = skin(rest, None, weights, transforms)
    expected = rest @ transforms[:, 7, :3, :3].transpose(-1, -2) + transforms[:, 7, None, :3, 3]
    assert torch.allclose(out, expected)


def test_broadcast_one_garment_many_frames():
    transforms = _random_transforms(4)
    rest = torch.randn(30, 3, dtype=torch.float64)
    weights = torch.softmax(torch.randn(30, 24, dtype=torch.float64), -1)
    out = skin(rest, None, weights, transforms)
    assert out.shape == (4, 30, 3)
    assert torch.allclose(out[2], skin(rest[None], None, weights[None], transforms[2:3])[0])


def test_ragged_batch_matches_dense():
    transforms = _random_transforms(2)
    sizes = (17, 9)
    rest = [torch.randn(n, 3, dtype=torch.float64) for n in sizes]
    weights = [torch.softmax(torch.randn(n, 24, dtype=torch.float64), -1) for n in sizes]
    batch = torch.cat([torch.full((n,), i) for i, n in enumerate(sizes)])
    out = skin(torch.cat(rest), None, torch.cat(weights), transforms, batch=batch)
    for i in range(len(sizes)):
        dense = skin(rest[i][None], None, weights[i][None], transforms[i : i + 1])[0]
        assert torch.allclose(out[batch == i], dense)
    assert out.shape == (sum(sizes), 3)
    # Items interleaved rather than in runs (and an item with no vertex): the same.
    order = torch.randperm(len(batch))
    with_empty = torch.cat([transforms[:1], _random_transforms(1), transforms[1:]])
    shuffled = skin(torch.cat(rest)[order], None, torch.cat(weights)[order], with_empty,
                    batch=torch.where(batch == 1, 2, batch)[order])
    assert torch.allclose(shuffled, out[order])
    gapped = skin(torch.cat(rest), None, torch.cat(weights), with_empty,
                  batch=torch.where(batch == 1, 2, batch))
    assert torch.allclose(gapped, out)


def test_gradcheck():
    transforms = _random_transforms(1).requires_grad_(True)
    rest = torch.randn(1, 6, 3, dtype=torch.float64, requires_grad=True)
    blend = torch.randn(1, 6, 3, dtype=torch.float64, requires_grad=True)
    logits = torch.randn(1, 6, 24, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(
        lambda r, b, w, g: skin(r, b, torch.softmax(w, -1), g), (rest, blend, logits, transforms)
    )
    rotvec = (0.3 * torch.randn(24, 3, dtype=torch.float64)).requires_grad_(True)
    rest_joints = torch.randn(24, 3, dtype=torch.float64)
    weights = torch.softmax(torch.randn(6, 24, dtype=torch.float64), -1)
    assert torch.autograd.gradcheck(
        lambda rv: skin(rest[0].detach(), None, weights, forward_kinematics(rv, rest_joints)[0]),
        (rotvec,),
    )


def test_axis_angle_gradient_at_zero_is_finite():
    rotvec = torch.zeros(24, 3, requires_grad=True)
    axis_angle_to_matrix(rotvec).sum().backward()
    assert torch.isfinite(rotvec.grad).all()


def test_validation():
    with pytest.raises(ValueError, match="weights"):
        skin(torch.zeros(5, 3), None, torch.zeros(5, 23), torch.eye(4).expand(24, 4, 4))
    with pytest.raises(ValueError, match="joint_transforms"):
        skin(torch.zeros(5, 3), None, torch.zeros(5, 24), torch.eye(4).expand(23, 4, 4))
    with pytest.raises(ValueError, match="vertex counts"):
        skin(
            torch.zeros(5, 3),
            None,
            torch.zeros(5, 24),
            torch.eye(4).expand(1, 24, 4, 4),
            batch=torch.zeros(4, dtype=torch.long),
        )
