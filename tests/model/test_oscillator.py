"""The per-vertex damped oscillators: stable for any parameters, the analytic response,
a state that carries after the drive stops, streaming equal to one pass, no drive at
rest, and gradients to every parameter."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from gnngarment.body.skeleton import NUM_JOINTS
from gnngarment.model.oscillator import (
    OscillatorHead,
    OscillatorParameters,
    OscillatorState,
    oscillator_drive,
    oscillator_response,
)

FPS = 30.0


def _parameters(n: int = 5, modes: int = 2, seed: int = 0, dtype=torch.float64):
    generator = torch.Generator().manual_seed(seed)
    torch.manual_seed(seed)   # the hidden layer's initialisation: the same case every run
    head = OscillatorHead(8, modes).to(dtype)
    with torch.no_grad():  # random, extreme raw outputs: every range limit is exercised
        head.output.weight.normal_(0, 5.0, generator=generator)
    return head(torch.randn(n, 8, generator=generator, dtype=dtype))


def test_any_parameters_give_a_bounded_response_that_decays() -> None:
    parameters = _parameters(n=64, seed=1)
    drive = torch.zeros(600, 64, 3, dtype=torch.float64)
    drive[:30] = 9.81 * torch.randn(30, 64, 3, generator=torch.Generator().manual_seed(2),
                                    dtype=torch.float64)
    response = oscillator_response(drive, parameters, FPS)
    assert torch.isfinite(response).all()
    bound = 30 * 9.81 * 5 * parameters.gain.abs().sum(1).max()
    assert response.abs().max() <= bound
    # Every mode decays at least as e^{-ζ_min ω_min t}: over the last 14 s, by that much
    # (a factor 2 for the phase of the envelope). Per mode: two nearly equal modes of
    # opposite gains cancel early and not late, so the sum's own early peak bounds
    # nothing; the modes' early peaks do (triangle inequality).
    head = OscillatorHead(8, 2)
    slowest = head.damping_range[0] * head.frequency_range[0]
    # (Early: the first 5 s, longer than the slowest mode's period.)
    early = 0
    for mode in range(parameters.gain.shape[1]):
        alone = parameters.gain.clone()
        alone[:, [k for k in range(alone.shape[1]) if k != mode]] = 0
        single = OscillatorParameters(parameters.frequency, parameters.damping, alone)
        early = early + oscillator_response(drive, single, FPS)[:150].abs().amax(0)
    late = response[-30:].abs().amax(0)
    assert (late <= 2 * math.exp(-slowest * 14.0) * early + 1e-12).all()


def test_impulse_response_is_the_sampled_damped_oscillator() -> None:
    omega, zeta = 2 * math.pi * 1.5, 0.1
    parameters = OscillatorParameters(torch.tensor([[omega]], dtype=torch.float64),
                                      torch.tensor([[zeta]], dtype=torch.float64),
                                      torch.ones(1, 1, 3, dtype=torch.float64))
    drive = torch.zeros(90, 1, 3, dtype=torch.float64)
    drive[0] = FPS  # a unit impulse of drive (1 m/s² for one frame = 1/FPS of m/s)
    response = oscillator_response(drive, parameters, FPS)[:, 0, 0].numpy()
    t = np.arange(90) / FPS
    damped = omega * math.sqrt(1 - zeta**2)
    analytic = omega**2 * np.exp(-zeta * omega * t) * np.sin(damped * t) / damped
    np.testing.assert_allclose(response, analytic, atol=1e-9)


def test_the_state_carries_after_the_drive_stops() -> None:
    """A body that stops abruptly: the response keeps swinging and decays with time
    constant 1 / (ζ ω)."""
    omega, zeta = 2 * math.pi * 1.0, 0.2
    parameters = OscillatorParameters(torch.tensor([[omega]], dtype=torch.float64),
                                      torch.tensor([[zeta]], dtype=torch.float64),
                                      torch.full((1, 1, 3), 0.01, dtype=torch.float64))
    drive = torch.zeros(150, 1, 3, dtype=torch.float64)
    drive[:30, 0, 0] = 5.0  # 1 s of acceleration, then still
    x = oscillator_response(drive, parameters, FPS)[:, 0, 0].numpy()
    after = x[31:]
    assert np.ptp(after[int(0.3 * FPS):]) > 0.3 * np.abs(x[:31]).max()  # still swinging
    peaks = [i for i in range(1, len(after) - 1)
             if abs(after[i]) >= abs(after[i - 1]) and abs(after[i]) >= abs(after[i + 1])]
    measured = (peaks[2] - peaks[0]) / FPS / math.log(abs(after[peaks[0]] / after[peaks[2]]))
    assert measured == pytest.approx(1 / (zeta * omega), rel=0.03)


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
@pytest.mark.parametrize("chunk", [1, 7, 16, 200])
def test_streaming_equals_one_pass(dtype, chunk: int) -> None:
    parameters = _parameters(n=40, seed=3, dtype=dtype)
    drive = 9.81 * torch.randn(200, 40, 3, generator=torch.Generator().manual_seed(4)).to(dtype)
    whole = oscillator_response(drive, parameters, FPS)
    state = OscillatorState.start(40, 2)
    pieces = []
    for start in range(0, 200, chunk):
        out, state = state.advance(drive[start:start + chunk], parameters, FPS)
        pieces.append(out)
    assert (torch.cat(pieces) - whole).abs().max() < 1e-5


def _rest_transforms(frames: int) -> torch.Tensor:
    return torch.eye(4, dtype=torch.float64).expand(frames, NUM_JOINTS, 4, 4).clone()


def test_no_drive_at_rest_and_gravity_when_tilted() -> None:
    generator = torch.Generator().manual_seed(5)
    rest = torch.randn(30, 3, generator=generator, dtype=torch.float64)
    weights = torch.softmax(torch.randn(30, NUM_JOINTS, generator=generator,
                                        dtype=torch.float64), 1)
    transforms = _rest_transforms(20)
    assert oscillator_drive(rest, weights, transforms, FPS).abs().max() < 1e-9
    # The whole body turned on its side (still): gravity now pulls along the frame's x.
    transforms[:, :, :3, :3] = torch.tensor([[0.0, 0, -1], [0, 1, 0], [1, 0, 0]],
                                            dtype=torch.float64)
    drive = oscillator_drive(rest, weights, transforms, FPS)[5:]
    expected = torch.tensor([9.81, 0.0, -9.81], dtype=torch.float64)
    assert torch.allclose(drive, expected.expand_as(drive), atol=1e-9)
    # A frame accelerating upwards at 2 m/s² (after the first frames) drives (0, 0, 2).
    moving = _rest_transforms(40)
    times = torch.arange(40, dtype=torch.float64) / FPS
    moving[:, :, 2, 3] = (times**2)[:, None]
    drive = oscillator_drive(rest, weights, moving, FPS)[3:]
    assert torch.allclose(drive, torch.tensor([0.0, 0, 2.0], dtype=torch.float64)
                          .expand_as(drive), atol=1e-6)


def test_head_starts_with_zero_gain_and_in_range() -> None:
    head = OscillatorHead(6, modes=3)
    parameters = head(torch.randn(10, 6))
    assert torch.equal(parameters.gain, torch.zeros(10, 3, 3))
    low, high = head.frequency_range
    assert (parameters.frequency > low).all() and (parameters.frequency < high).all()
    assert (parameters.damping > 0).all() and (parameters.damping < 1).all()


def test_gradients_reach_frequency_damping_and_gain() -> None:
    drive = torch.randn(12, 2, 3, generator=torch.Generator().manual_seed(6), dtype=torch.float64)

    def displacement(frequency, damping, gain):
        return oscillator_response(drive, OscillatorParameters(frequency, damping, gain), FPS)

    frequency = torch.tensor([[3.0, 9.0], [5.0, 2.0]], dtype=torch.float64, requires_grad=True)
    damping = torch.tensor([[0.2, 0.5], [0.7, 0.1]], dtype=torch.float64, requires_grad=True)
    gain = torch.randn(2, 2, 3, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(displacement, (frequency, damping, gain))
