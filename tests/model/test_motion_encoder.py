"""E^t1 / E^t2 (:class:`MotionEncoder`): an LSTM code of a window of frames."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from gnngarment.model.motion_encoder import MotionEncoder

CHANNELS, HIDDEN, LAYERS, WINDOW = 75, 12, 2, 5


@pytest.fixture(scope="module")
def encoder() -> MotionEncoder:
    torch.manual_seed(0)
    return MotionEncoder(CHANNELS, HIDDEN, LAYERS)


def windows(batch: int = 3, seed: int = 0) -> torch.Tensor:
    return 0.3 * torch.randn(batch, WINDOW, CHANNELS,
                             generator=torch.Generator().manual_seed(seed))


def close(actual: torch.Tensor, expected: torch.Tensor) -> None:
    np.testing.assert_allclose(actual.detach().numpy(), expected.detach().numpy(),
                               rtol=1e-5, atol=1e-6)


def test_the_code_is_the_last_hidden_state_of_the_top_layer(encoder: MotionEncoder) -> None:
    code, (hidden, cell) = encoder(windows())
    assert code.shape == (3, HIDDEN)
    assert hidden.shape == cell.shape == (LAYERS, 3, HIDDEN)
    close(code, hidden[-1])
    assert code.abs().max() > 1e-3


def test_streaming_with_the_state_equals_reading_the_whole_window(
        encoder: MotionEncoder) -> None:
    w = windows()
    whole, (hidden, cell) = encoder(w)
    _, state = encoder(w[:, :2])
    for t in range(2, WINDOW):  # one frame at a time, carrying the state
        code, state = encoder(w[:, t:t + 1], state)
    close(code, whole)
    close(state[0], hidden)
    close(state[1], cell)


def test_each_code_depends_on_its_own_window_only(encoder: MotionEncoder) -> None:
    w = windows()
    code, _ = encoder(w)
    other = w.clone()
    other[0] += 1.0
    changed, _ = encoder(other)
    close(changed[1:], code[1:])
    assert (changed[0] - code[0]).abs().max() > 1e-4
    close(encoder(w[2:3])[0][0], code[2])


def test_every_frame_of_the_window_counts_in_order(encoder: MotionEncoder) -> None:
    w = windows(1)
    code, _ = encoder(w)
    oldest = w.clone()
    oldest[:, 0] += 1.0
    assert (encoder(oldest)[0] - code).abs().max() > 1e-5
    assert (encoder(w.flip(1))[0] - code).abs().max() > 1e-4


def test_velocity_encoder_widths() -> None:
    # E^t2: 3 N_b' velocities per frame in, S·F channels out.
    velocity = MotionEncoder(3 * 32, 24 * 4, 1)
    code, (hidden, _) = velocity(torch.randn(6, 3, 3 * 32))
    assert code.shape == (6, 96) and hidden.shape == (1, 6, 96)


def test_reset_parameters_zeroes_biases_and_bounds_weights() -> None:
    encoder = MotionEncoder(CHANNELS, HIDDEN, LAYERS)
    with torch.no_grad():
        for parameter in encoder.parameters():
            parameter.fill_(7.0)
    encoder.reset_parameters()
    for name, parameter in encoder.lstm.named_parameters():
        if name.startswith("bias"):
            assert (parameter == 0).all(), name
        else:  # Kaiming uniform, linear gain: U(-sqrt(3 / fan_in), sqrt(3 / fan_in))
            bound = math.sqrt(3.0 / parameter.shape[1])
            assert parameter.abs().max() <= bound, name
            assert parameter.abs().max() > 0.5 * bound, name
    # Zero biases: a still window (all zeros) codes to zero.
    code, _ = encoder(torch.zeros(2, WINDOW, CHANNELS))
    assert (code == 0).all()
