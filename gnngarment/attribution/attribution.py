"""The result of an attribution: ``R`` (Eq. 9) with its target and completeness check."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

#: Column ranges of the graph features (:func:`garment_vertex_features`).
FEATURE_GROUPS: dict[str, slice] = {
    "position": slice(0, 3), "normal": slice(3, 6), "joint_distances": slice(6, 30)}

#: Target kinds of :func:`~gnngarment.attribution.attribute`.
TARGET_KINDS = ("vertex", "region", "all")
#: Model outputs an attribution can explain.
OUTPUTS = ("blend_shapes", "posed")
#: How a vertex's 3-vector output becomes a scalar.
REDUCTIONS = ("norm", "sum")
#: Channel sets a heatmap can be made of: the paper's normals, or every channel.
HEAT_CHANNELS = ("normal", "all")


@dataclass
class Attribution:
    """Integrated-gradients attribution of one scalar model output to the garment graph
    features ``X`` (paper Eq. 9).

    Attributes:
        attributions: ``(N, 30)`` ``R``, same layout as the features (position, normal,
            24 joint distances); in units of the target (metres).
        target: ``"vertex"``, ``"region"`` or ``"all"``.
        target_vertices: ``(K,)`` vertices whose outputs make the target (all ``N`` for
            ``"all"``).
        output: ``"blend_shapes"`` or ``"posed"``.
        reduction: ``"norm"`` or ``"sum"`` of each target vertex's 3-vector.
        value: ``f(X)``, the target at the actual features (metres).
        baseline_value: ``f(0)``, the target at the zero baseline.
        delta: captum's convergence delta ``ΣR − (f(X) − f(0))`` (completeness error of
            the Gauss–Legendre quadrature).
        n_steps: quadrature points ``N_s``.
        seconds: wall-clock of the attribution.
    """

    attributions: np.ndarray
    target: str
    target_vertices: np.ndarray
    output: str
    reduction: str
    value: float
    baseline_value: float
    delta: float
    n_steps: int
    seconds: float

    @property
    def num_vertices(self) -> int:
        return int(self.attributions.shape[0])

    @property
    def relative_delta(self) -> float:
        """``|delta| / |f(X) − f(0)|``: the completeness error as a fraction of what
        the attributions explain (0 when both are 0)."""
        change = abs(self.value - self.baseline_value)
        if change == 0.0:
            return 0.0 if self.delta == 0.0 else float("inf")
        return abs(self.delta) / change

    def heat(self, channels: str = "normal") -> np.ndarray:
        """``(N,)`` per-vertex heat: ``Σ|R|`` over the normal channels (the paper's
        heatmap) or over all 30 channels.

        Raises:
            ValueError: unknown ``channels``.
        """
        if channels == "normal":
            return self.channel_totals()["normal"]
        if channels == "all":
            return np.abs(self.attributions).sum(axis=1)
        raise ValueError(f"unknown heat channels '{channels}' (expected one of {HEAT_CHANNELS})")

    def channel_totals(self) -> dict[str, np.ndarray]:
        """``(N,)`` ``Σ|R|`` of every feature group (position, normal, joint distances)."""
        magnitude = np.abs(self.attributions)
        return {name: magnitude[:, columns].sum(axis=1) for name, columns in FEATURE_GROUPS.items()}

    def summary(self) -> dict[str, Any]:
        """JSON-ready numbers: target, completeness and each group's share of ``Σ|R|``."""
        totals = {name: float(v.sum()) for name, v in self.channel_totals().items()}
        everything = sum(totals.values()) or 1.0
        return {
            "target": self.target, "output": self.output, "reduction": self.reduction,
            "target_vertices": self.target_vertices.tolist() if self.target != "all"
            else f"all {self.num_vertices}",
            "value": self.value, "baseline_value": self.baseline_value,
            "sum_of_attributions": float(self.attributions.sum()),
            "delta": self.delta, "relative_delta": self.relative_delta,
            "n_steps": self.n_steps, "seconds": self.seconds,
            "abs_share": {name: total / everything for name, total in totals.items()},
        }

    def save(self, path: str | Path) -> Path:
        """Write everything to one ``.npz`` (atomically)."""
        from gnngarment.io.npz import save_npz_atomic

        path = Path(path)
        save_npz_atomic(path, {
            "attributions": self.attributions, "target_vertices": self.target_vertices,
            "target": np.array(self.target), "output": np.array(self.output),
            "reduction": np.array(self.reduction), "value": np.array(self.value),
            "baseline_value": np.array(self.baseline_value), "delta": np.array(self.delta),
            "n_steps": np.array(self.n_steps), "seconds": np.array(self.seconds)})
        return path

    @classmethod
    def load(cls, path: str | Path) -> Attribution:
        """Read a file written by :meth:`save`.

        Raises:
            ValueError: missing or corrupt file, or arrays absent (names the file).
        """
        from gnngarment.io.npz import load_npz

        names = ("attributions", "target_vertices", "target", "output", "reduction", "value",
                 "baseline_value", "delta", "n_steps", "seconds")
        data = load_npz(path, required=names)
        return cls(attributions=data["attributions"], target_vertices=data["target_vertices"],
                   target=str(data["target"]), output=str(data["output"]),
                   reduction=str(data["reduction"]), value=float(data["value"]),
                   baseline_value=float(data["baseline_value"]), delta=float(data["delta"]),
                   n_steps=int(data["n_steps"]), seconds=float(data["seconds"]))
