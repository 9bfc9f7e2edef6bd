"""How much of what fixed skinning weights leave is a linear, time-invariant response to
the motion: the bound on what a per-vertex dynamics module can win, measured before
building one (as ``skinning_bounds.py`` did for the weights).

For every held-out (design, body) pair of a split that was simulated with several
motions (``configs/data/benchmark_cmu.yaml``: one procedural and two CMU windows each),
E_verts (mm, mean per-vertex distance to the simulated garment over all frames) of:

* ``body skinning``: the draped template skinned with the body's transferred weights;
* ``weights (self)``: per-vertex weights fitted to the sequence's own frames
  (``skinning_bounds.fit_weights``), the lowest error fixed weights reach;
* ``+ LTI (self)``: those weights plus a per-vertex linear time-invariant response to
  the motion, fitted to the same sequence's residual: the bound;
* ``weights (other)`` and ``+ LTI (other)``: weights, then the response, fitted to the
  pair's *other* motions and evaluated on this one: what a model that knew this garment
  perfectly from other motions could do — the transfer a learned module can hope for.

The response: the residual ``y_t − LBS_t(w)`` taken into each vertex's skinning frame
(the rest-frame offset that LBS would carry onto it, ``A_i(t)^-1 r``), regressed on the
vertex's **drive** (``gnngarment.model.oscillator.oscillator_drive``: the skinning
frame's linear acceleration minus gravity, in that frame, zero at rest) and the frame's
**angular velocity** (in that frame), each passed through a fixed bank of causal filters:
the impulse responses of damped oscillators at 0.5, 1, 2 and 4 Hz with damping ratios
0.15 and 0.6, plus the instantaneous value. A sum of fixed-pole second-order filters
with per-vertex gains is exactly the class of a modal dynamics module. ``--coupling
diagonal`` lets each offset axis see only the same axis of the inputs (what a per-axis
oscillator can express); ``full`` lets every axis see every input axis; ``pose``
regresses on the vertex's joints' rotations instead (:func:`pose_features`, SMPL's pose
blend shape class) and ``diagonal+pose`` on both. Ridge ``λ``
(``--ridge``, on inputs scaled to unit variance) keeps the self-fit from memorising.

    .venv/bin/python benchmarks/dynamics_bounds.py [--data data/benchmark_cmu]
        [--split test] [--coupling diagonal full] [--ridge 1.0]

Numpy/scipy with the drive from torch; a few minutes for the 36 test sequences on one core.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "benchmarks"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

from skinning_bounds import blend, fit_weights, joint_positions, vertex_error_mm  # noqa: E402

from gnngarment.data import PreparedDataset  # noqa: E402

#: The filter bank: natural frequencies (Hz) × damping ratios of its oscillators.
BANK_FREQUENCIES = (0.5, 1.0, 2.0, 4.0)
BANK_DAMPING = (0.15, 0.6)


def filter_bank(frames: int, fps: float) -> np.ndarray:
    """Impulse responses ``(K, frames)`` of the bank: a unit impulse (the instantaneous
    term) and every damped oscillator's displacement response, each scaled to unit peak."""
    t = np.arange(frames) / fps
    bank = [np.eye(1, frames)[0]]
    for frequency in BANK_FREQUENCIES:
        omega = 2 * np.pi * frequency
        for zeta in BANK_DAMPING:
            damped = omega * np.sqrt(1 - zeta**2)
            response = np.exp(-zeta * omega * t) * np.sin(damped * t)
            bank.append(response / np.abs(response).max())
    return np.stack(bank)


def causal_filter(signal: np.ndarray, bank: np.ndarray) -> np.ndarray:
    """Every input filtered by every bank filter: ``(T, N, C)`` → ``(T, N, C, K)``."""
    frames = signal.shape[0]
    length = 2 * frames
    spectrum = np.fft.rfft(signal, n=length, axis=0)
    kernels = np.fft.rfft(bank, n=length, axis=1)                         # (K, F)
    out = np.fft.irfft(spectrum[..., None] * kernels.T[:, None, None, :], n=length, axis=0)
    return out[:frames]


def blended_frames(transforms: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Each vertex's blended skinning matrix ``A_i(t) = Σ_j w_ij R_j(t)``: ``(T, N, 3, 3)``."""
    return np.einsum("nj,tjab->tnab", weights, transforms[:, :, :3, :3])


def angular_velocity(frames: np.ndarray, fps: float) -> np.ndarray:
    """Angular velocity (rad/s) of each vertex's skinning frame, in that frame, by central
    differences of its nearest rotation (polar factor of ``A``): ``(T, N, 3)``."""
    u, _, vt = np.linalg.svd(frames)
    rotation = u @ vt
    padded = np.concatenate([rotation[:1], rotation, rotation[-1:]])
    # Ω = Rᵀ Ṙ is skew-symmetric; its axial vector is the body-frame angular velocity.
    derivative = (padded[2:] - padded[:-2]) * (fps / 2)
    omega = np.swapaxes(rotation, -1, -2) @ derivative
    return np.stack([omega[..., 2, 1] - omega[..., 1, 2], omega[..., 0, 2] - omega[..., 2, 0],
                     omega[..., 1, 0] - omega[..., 0, 1]], axis=-1) / 2


class Sequence:
    """What the fits need of one simulated sequence (float64, metres): the rest template
    ``(N, 3)``, its body weights ``(N, J)``, the joint transforms ``(T, J, 4, 4)`` and the
    simulated answer ``(T, N, 3)`` at ``fps``."""

    def __init__(self, name: str, garment_type: str, motion: str, rest: np.ndarray,
                 prior: np.ndarray, transforms: np.ndarray, target: np.ndarray, fps: float):
        import torch

        from gnngarment.model.oscillator import oscillator_drive

        self.name, self.type, self.motion = name, garment_type, motion
        self.rest = rest.astype(np.float64)
        self.prior = prior.astype(np.float64)
        self.transforms = transforms.astype(np.float64)
        self.per_joint = joint_positions(self.rest, self.transforms)
        self.target = target.astype(np.float64)
        with torch.no_grad():
            drive = oscillator_drive(torch.as_tensor(self.rest), torch.as_tensor(self.prior),
                                     torch.as_tensor(self.transforms), fps).numpy()
        omega = angular_velocity(blended_frames(self.transforms, self.prior), fps)
        bank = filter_bank(len(self.target), fps)
        # (T, N, 6 inputs, K filters): the regressors of every vertex and frame.
        self.inputs = causal_filter(np.concatenate([drive, omega], axis=-1), bank)

    @classmethod
    def from_dataset(cls, dataset: PreparedDataset, name: str) -> Sequence:
        garment = dataset.garment_of(name)
        sequence = dataset.sequence(name)
        info = dataset.manifest["sequences"][name]
        return cls(name, garment.garment_type, info["motion"], garment.pair.rest_pos.numpy(),
                   garment.pair.body_weights.numpy(), sequence.joint_transforms,
                   sequence.positions, float(info.get("fps", sequence.fps)))

    def skinned(self, weights: np.ndarray) -> np.ndarray:
        return blend(self.per_joint, weights)

    def local_residual(self, weights: np.ndarray) -> np.ndarray:
        """``(T, N, 3)`` the rest-frame offsets LBS would carry onto the residual."""
        residual = self.target - self.skinned(weights)
        frames = blended_frames(self.transforms, weights)
        return np.linalg.solve(frames, residual[..., None])[..., 0]


#: How many of a vertex's most-weighted joints the ``pose`` regressors read.
POSE_JOINTS = 3


def local_rotations(transforms: np.ndarray) -> np.ndarray:
    """``(T, J, 3, 3)`` ``R − I`` of every joint's rotation relative to its parent, from
    ``(T, J, 4, 4)`` skinning transforms; zero for the root (its global rotation is not a
    pose)."""
    from gnngarment.body.skeleton import JOINT_PARENTS

    rotation = transforms[..., :3, :3]
    parents = np.array([max(p, 0) for p in JOINT_PARENTS])
    local = np.swapaxes(rotation[:, parents], -1, -2) @ rotation - np.eye(3)
    local[:, 0] = 0.0
    return local


def pose_features(transforms: np.ndarray, prior: np.ndarray) -> np.ndarray:
    """``(T, N, 9 POSE_JOINTS)`` the quasi-static regressors of every vertex: the
    :func:`local_rotations` of its :data:`POSE_JOINTS` most-weighted joints, the
    linear-in-``R`` class of SMPL's pose blend shapes."""
    top = np.argsort(-prior, axis=1)[:, :POSE_JOINTS]                       # (N, K)
    return local_rotations(transforms)[:, top].reshape(len(transforms), len(prior), -1)


def _design(sequence: Sequence, axis: int, coupling: str) -> np.ndarray:
    """Per-vertex regressors ``(N, T, P)`` of output ``axis``: ``full``, all six inputs ×
    filters; ``diagonal``, the drive's and angular velocity's same axis only; ``pose``,
    :func:`pose_features`; ``diagonal+pose``, both."""
    parts = []
    if coupling in ("full", "diagonal", "diagonal+pose"):
        inputs = sequence.inputs if coupling == "full" else sequence.inputs[:, :, [axis, 3 + axis]]
        parts.append(inputs.reshape(*inputs.shape[:2], -1))
    if coupling.endswith("pose"):
        parts.append(pose_features(sequence.transforms, sequence.prior))
    return np.transpose(np.concatenate(parts, axis=-1), (1, 0, 2))


def fit_response(train: list[Sequence], weights: list[np.ndarray], coupling: str,
                 ridge: float) -> list[np.ndarray]:
    """Per-vertex ridge regression of the local residual on the regressors of
    ``coupling`` (:func:`_design`): one coefficient array per output axis, ``(N, P)``."""
    coefficients = []
    for axis in range(3):
        x = np.concatenate([_design(s, axis, coupling) for s in train], axis=1)  # (N, ΣT, P)
        y = np.concatenate([s.local_residual(w)[..., axis].T for s, w in zip(train, weights,
                                                                              strict=True)],
                           axis=1)                                            # (N, ΣT)
        scale = x.std(axis=1, keepdims=True) + 1e-12
        x = x / scale
        gram = np.einsum("ntp,ntq->npq", x, x) + ridge * np.eye(x.shape[2])
        solution = np.linalg.solve(gram, np.einsum("ntp,nt->np", x, y)[..., None])[..., 0]
        coefficients.append(solution / scale[:, 0])
    return coefficients


def with_response(sequence: Sequence, weights: np.ndarray, coefficients: list[np.ndarray],
                  coupling: str) -> np.ndarray:
    """``(T, N, 3)`` the garment skinned with ``weights`` plus the fitted response."""
    offsets = np.stack([np.einsum("ntp,np->tn", _design(sequence, axis, coupling), c)
                        for axis, c in enumerate(coefficients)], axis=-1)
    carried = np.einsum("tnab,tnb->tna", blended_frames(sequence.transforms, weights), offsets)
    return sequence.skinned(weights) + carried


def evaluate_pair(sequences: list[Sequence], couplings: list[str], ridge: float) -> list[dict]:
    rows = []
    own = [fit_weights([s.per_joint], [s.target], s.prior) for s in sequences]
    for k, sequence in enumerate(sequences):
        others = [s for i, s in enumerate(sequences) if i != k]
        other_weights = fit_weights([s.per_joint for s in others], [s.target for s in others],
                                    sequence.prior)
        row = {"sequence": sequence.name, "type": sequence.type,
               "source": "cmu" if sequence.motion.startswith("clip") else "procedural",
               "body skinning": vertex_error_mm(sequence.skinned(sequence.prior),
                                                sequence.target),
               "weights (self)": vertex_error_mm(sequence.skinned(own[k]), sequence.target),
               "weights (other)": vertex_error_mm(sequence.skinned(other_weights),
                                                  sequence.target)}
        for coupling in couplings:
            self_fit = fit_response([sequence], [own[k]], coupling, ridge)
            row[f"+ LTI {coupling} (self)"] = vertex_error_mm(
                with_response(sequence, own[k], self_fit, coupling), sequence.target)
            # The other motions' residuals under the weights fitted to them.
            other_fit = fit_response(others, [other_weights] * len(others), coupling, ridge)
            row[f"+ LTI {coupling} (other)"] = vertex_error_mm(
                with_response(sequence, other_weights, other_fit, coupling), sequence.target)
        rows.append(row)
        print("  " + sequence.name + ": " + ", ".join(
            f"{key} {value:.2f}" for key, value in row.items() if isinstance(value, float)),
            file=sys.stderr, flush=True)
    return rows


def table(rows: list[dict], columns: list[str], group: str) -> None:
    print(f"| {group} | sequences | " + " | ".join(f"{c} mm" for c in columns) + " |")
    print("|---|---|" + "---|" * len(columns))
    for kind in [*sorted({row[group] for row in rows}), "all"]:
        chosen = [row for row in rows if kind in ("all", row[group])]
        base = np.mean([row[columns[0]] for row in chosen])
        cells = [f"{np.mean([row[c] for row in chosen]):.2f}" + (
            f" ({np.mean([row[c] for row in chosen]) / base:.2f}x)" if c != columns[0] else "")
            for c in columns]
        print(f"| {kind} | {len(chosen)} | " + " | ".join(cells) + " |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT / "data" / "benchmark_cmu")
    parser.add_argument("--split", default="test")
    parser.add_argument("--coupling", nargs="+", default=["diagonal", "full"],
                        choices=["diagonal", "full", "pose", "diagonal+pose"])
    parser.add_argument("--ridge", type=float, default=1.0)
    parser.add_argument("--pairs", type=int, default=0, help="at most this many pairs (0: all)")
    args = parser.parse_args()
    if not (args.data / "manifest.json").is_file():
        print(f"{args.data}: no prepared cache (build it with `gnngarment prepare`)",
              file=sys.stderr)
        raise SystemExit(2)
    dataset = PreparedDataset(args.data, args.split, 1)
    by_pair: dict[tuple[str, str], list[str]] = defaultdict(list)
    for name in dataset.sequence_names:
        info = dataset.manifest["sequences"][name]
        by_pair[(info["garment"], info["body"])].append(name)
    pairs = [names for names in by_pair.values() if len(names) >= 2]
    if args.pairs:
        pairs = pairs[:args.pairs]
    rows = []
    for names in pairs:
        rows += evaluate_pair([Sequence.from_dataset(dataset, name) for name in names],
                              args.coupling, args.ridge)
    columns = ["body skinning", "weights (self)"]
    columns += [f"+ LTI {c} (self)" for c in args.coupling] + ["weights (other)"]
    columns += [f"+ LTI {c} (other)" for c in args.coupling]
    print(f"## {args.split} split of {args.data}: {len(rows)} sequences of {len(pairs)} "
          f"pairs, ridge {args.ridge:g}; ratios to body skinning")
    table(rows, columns, "type")
    print()
    table(rows, columns, "source")


if __name__ == "__main__":
    main()
