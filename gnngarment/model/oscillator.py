"""Per-vertex driven, damped oscillators: the motion-dependent part of the blend shapes
that a garment keeps after the body stops (a hem that swings, lags and settles).

Every vertex carries ``K`` second-order modes in the frame of its skinning transform,

    x_k'' + 2 ζ_k ω_k x_k' + ω_k² x_k = ω_k² s_k ⊙ u(t),        displacement = Σ_k x_k,

driven by :func:`oscillator_drive` ``u`` (m/s²): the inertial acceleration that frame
undergoes and gravity in it, zero for a body at rest in the rest pose. ``s_k`` (3,) is
the static displacement per unit drive (m per m/s², a signed per-axis gain), ω_k the
natural frequency (rad/s), ζ_k the damping ratio. A network predicts ω, ζ, s per vertex
from the garment–body features (:class:`OscillatorHead`), within ranges that make every
mode damped (ζ ≥ ``min_damping`` > 0) and bounded.

**Discretisation.** The continuous impulse response sampled at the frames (impulse
invariance), ``h[k] = Δt · e^{−ζωkΔt} sin(ω_d kΔt) / ω_d`` for ``k ≥ 1`` (``h[0] = 0``:
a frame's drive moves the garment from the next frame on), is exactly the 2nd-order
recursion ``x[t] = 2r cos θ · x[t−1] − r² · x[t−2] + b · u[t−1]`` with ``r = e^{−ζωΔt}``,
``θ = ω_d Δt``, ``b = Δt r sin θ / ω_d``. Its poles have modulus ``r < 1`` for any
ω, ζ > 0 and any Δt: stable unconditionally.

**Evaluation.** Linear in its drive, a whole sequence is one causal convolution
(:func:`oscillator_response`, by FFT along time), so a training batch of randomly chosen
frames costs one pass over each sequence's history; :class:`OscillatorState` runs the
recursion frame by frame for streaming inference. Both give the same displacement (a
test: within 1e-5 m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
from torch import nn

from gnngarment.body.skeleton import NUM_JOINTS

#: Gravity (m/s², Z up), as the reference simulator's.
GRAVITY = (0.0, 0.0, -9.81)


def oscillator_drive(rest_pos: torch.Tensor, weights: torch.Tensor,
                     joint_transforms: torch.Tensor, fps: float,
                     gravity: tuple[float, float, float] = GRAVITY) -> torch.Tensor:
    """The drive of every vertex's oscillators over a sequence (m/s²).

    The vertex's skinning transform ``A_i(t) = Σ_j w_ij G_j(t)`` moves its rest position
    to ``p_i(t)``; the drive is ``u = A_iᵀ (p̈_i − g) + g``: the frame's acceleration minus
    gravity, seen in the frame (``A_iᵀ`` carries world vectors into it; LBS carries a
    rest-frame offset out by ``A_i``, so the oscillators' displacement is a rest-frame
    blend shape), minus its value at rest (``A = I``, ``p̈ = 0``: ``−g``), so a body
    standing still in the rest pose drives nothing — the template is already draped under
    gravity. ``A_iᵀ`` rather than ``A_i⁻¹``: a blend of rotations is close to one, and its
    transpose cannot blow up where blending shrinks it.

    The acceleration is the backward difference ``(p_t − 2p_{t−1} + p_{t−2}) · fps²``,
    frames before 0 being frame 0 (the body was still before the motion): causal, so a
    stream of frames gets the same drive as the whole sequence.

    Shapes: rest_pos ``(N, 3)`` m, weights ``(N, 24)``, joint_transforms
    ``(T, 24, 4, 4)`` → ``(T, N, 3)``.
    """
    if joint_transforms.shape[1:] != (NUM_JOINTS, 4, 4) or weights.shape[-1] != NUM_JOINTS:
        raise ValueError(f"joint_transforms must be (T, {NUM_JOINTS}, 4, 4) and weights "
                         f"(N, {NUM_JOINTS}), got {tuple(joint_transforms.shape)}, "
                         f"{tuple(weights.shape)}")
    dtype = joint_transforms.dtype
    weights = weights.to(dtype)
    blended = torch.einsum("nj,tjab->tnab", weights, joint_transforms)        # (T, N, 4, 4)
    frame = blended[..., :3, :3]
    position = (frame @ rest_pos.to(dtype)[None, :, :, None])[..., 0] + blended[..., :3, 3]
    padded = torch.cat([position[:1], position[:1], position])
    acceleration = (padded[2:] - 2 * padded[1:-1] + padded[:-2]) * fps**2
    g = torch.tensor(gravity, dtype=dtype, device=joint_transforms.device)
    local = (frame.transpose(-1, -2) @ (acceleration - g)[..., None])[..., 0]
    return local + g


@dataclass
class OscillatorParameters:
    """Per-vertex modes.

    Attributes:
        frequency: ``(N, K)`` natural frequencies ω (rad/s).
        damping: ``(N, K)`` damping ratios ζ in (0, 1).
        gain: ``(N, K, 3)`` static displacement per unit drive (m per m/s²).
    """

    frequency: torch.Tensor
    damping: torch.Tensor
    gain: torch.Tensor

    def recursion(self, fps: float) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """``(a1, a2, b)``, each ``(N, K)``: ``x[t] = a1 x[t−1] + a2 x[t−2] + b ω² s u[t−1]``."""
        step = 1.0 / fps
        damped = self.frequency * torch.sqrt(1 - self.damping**2)
        radius = torch.exp(-self.damping * self.frequency * step)
        angle = damped * step
        return (2 * radius * torch.cos(angle), -radius**2,
                step * radius * torch.sin(angle) / damped)

    def impulse_response(self, frames: int, fps: float) -> torch.Tensor:
        """``(frames, N, K)`` ``h[k]`` of every mode (``h[0] = 0``), times ω² (so a unit
        ``gain`` is a unit static displacement)."""
        step = 1.0 / fps
        k = torch.arange(frames, dtype=self.frequency.dtype,
                         device=self.frequency.device)[:, None, None]
        damped = self.frequency * torch.sqrt(1 - self.damping**2)
        decay = torch.exp(-self.damping * self.frequency * step * k)
        return step * decay * torch.sin(damped * step * k) / damped * self.frequency**2


def oscillator_response(drive: torch.Tensor, parameters: OscillatorParameters,
                        fps: float) -> torch.Tensor:
    """Displacement ``Σ_k x_k`` (m, rest frame) of every vertex over a whole sequence,
    started at rest: the causal convolution of the drive with each mode's impulse
    response, computed by FFT along time.

    Shapes: drive ``(T, N, 3)`` → ``(T, N, 3)``.
    """
    frames, dtype = drive.shape[0], drive.dtype
    # In float64: a float32 FFT's error grows with the sequence's largest value, and the
    # result must equal the frame-by-frame recursion within 1e-5 m (it is cheap: T·N·K).
    wide = OscillatorParameters(parameters.frequency.double(), parameters.damping.double(),
                                parameters.gain.double())
    response = wide.impulse_response(frames, fps)                            # (T, N, K)
    length = 2 * frames  # zero padding: a linear, not circular, convolution
    drive_spectrum = torch.fft.rfft(drive.double(), n=length, dim=0)         # (F, N, 3)
    kernel = torch.fft.rfft(response, n=length, dim=0)                       # (F, N, K)
    # Σ_k gain_k · (h_k * u): the modes' kernels summed per axis first (linearity).
    combined = torch.einsum("fnk,nka->fna", kernel, wide.gain.to(kernel.dtype))
    return torch.fft.irfft(combined * drive_spectrum, n=length, dim=0)[:frames].to(dtype)


@dataclass
class OscillatorState:
    """The state a stream of frames carries: the last two displacements of every mode
    ``(N, K, 3)`` and the last drive ``(N, 3)``; :meth:`start` for a body at rest.

    Kept in float64 whatever the model's dtype: a lightly damped mode run for thousands
    of frames would otherwise drift from the one-pass response by float32 rounding."""

    previous: torch.Tensor
    before_previous: torch.Tensor
    last_drive: torch.Tensor

    @classmethod
    def start(cls, vertices: int, modes: int,
              device: torch.device | str = "cpu") -> OscillatorState:
        zeros = torch.zeros(vertices, modes, 3, dtype=torch.float64, device=device)
        return cls(zeros, zeros.clone(),
                   torch.zeros(vertices, 3, dtype=torch.float64, device=device))

    def advance(self, drive: torch.Tensor, parameters: OscillatorParameters,
                fps: float) -> tuple[torch.Tensor, OscillatorState]:
        """Displacements ``(T, N, 3)`` of the next ``T`` frames of drive ``(T, N, 3)``, and
        the state after them (the recursion of :meth:`OscillatorParameters.recursion`)."""
        wide = OscillatorParameters(parameters.frequency.double(),
                                    parameters.damping.double(), parameters.gain.double())
        a1, a2, b = (c[..., None] for c in wide.recursion(fps))
        scale = b * wide.frequency[..., None] ** 2 * wide.gain                # (N, K, 3)
        previous, before, last = self.previous, self.before_previous, self.last_drive
        out = []
        for frame in drive.double():
            current = a1 * previous + a2 * before + scale * last[:, None, :]
            out.append(current.sum(dim=1))
            previous, before, last = current, previous, frame
        return torch.stack(out).to(drive.dtype), OscillatorState(previous, before, last)


class OscillatorHead(nn.Module):
    """Per-vertex features → the modes' frequency, damping and gain.

    Args:
        in_channels: feature channels per vertex.
        modes: ``K``.
        hidden: width of the hidden layer.
        frequency_range: (ω_min, ω_max) rad/s; damping_range: (ζ_min, ζ_max) in (0, 1);
        max_gain: bound of ``|s|`` (m per m/s²).

    The output layer starts at zero: gains are exactly 0 (a warm-started model is
    unchanged), frequencies and dampings mid-range.
    """

    def __init__(self, in_channels: int, modes: int, hidden: int = 64,
                 frequency_range: tuple[float, float] = (2 * math.pi * 0.3, 2 * math.pi * 6.0),
                 damping_range: tuple[float, float] = (0.05, 0.95), max_gain: float = 0.02):
        super().__init__()
        if not 0 < frequency_range[0] < frequency_range[1]:
            raise ValueError(f"frequency_range must be 0 < low < high, got {frequency_range}")
        if not 0 < damping_range[0] < damping_range[1] < 1:
            raise ValueError(f"damping_range must be 0 < low < high < 1, got {damping_range}")
        self.modes = modes
        self.frequency_range = frequency_range
        self.damping_range = damping_range
        self.max_gain = max_gain
        self.hidden = nn.Sequential(nn.Linear(in_channels, hidden), nn.ReLU())
        self.output = nn.Linear(hidden, modes * 5)
        nn.init.zeros_(self.output.weight)
        nn.init.zeros_(self.output.bias)
        with torch.no_grad():
            # Modes spread over the frequency range at start (log-spaced).
            self.output.bias[:modes] = torch.logit(
                torch.linspace(0.2, 0.8, modes) if modes > 1 else torch.tensor([0.5]))

    def forward(self, features: torch.Tensor) -> OscillatorParameters:
        """Shapes: features ``(N, C)`` → :class:`OscillatorParameters` of ``N`` vertices."""
        raw = self.output(self.hidden(features)).view(-1, 5, self.modes)
        low, high = self.frequency_range
        frequency = low * (high / low) ** torch.sigmoid(raw[:, 0])
        zeta_low, zeta_high = self.damping_range
        damping = zeta_low + (zeta_high - zeta_low) * torch.sigmoid(raw[:, 1])
        gain = self.max_gain * torch.tanh(raw[:, 2:].transpose(1, 2))          # (N, K, 3)
        return OscillatorParameters(frequency, damping, gain)
