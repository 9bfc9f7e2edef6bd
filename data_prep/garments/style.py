"""Style parameters: a frozen dataclass per garment type, with sampling ranges.

Each field is either a float with a ``(low, high)`` range or a string with a tuple of
choices, declared in the field's metadata; construction validates the values, and
:meth:`Style.sample` draws every field uniformly from its range.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any, ClassVar, TypeVar

import numpy as np

S = TypeVar("S", bound="Style")


def number(default: float, low: float, high: float, doc: str) -> Any:
    """A float style field in ``[low, high]`` (``doc`` says what it is and its unit)."""
    return dataclasses.field(default=default, metadata={"range": (low, high), "doc": doc})


def choice(default: str, options: tuple[str, ...], doc: str,
           weights: tuple[float, ...] | None = None) -> Any:
    """A string style field, one of ``options`` (sampled with ``weights``)."""
    return dataclasses.field(default=default, metadata={"choices": options, "doc": doc,
                                                        "weights": weights})


@dataclasses.dataclass(frozen=True)
class Style:
    """Base class of the per-type style dataclasses."""

    garment_type: ClassVar[str] = ""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if "range" in f.metadata:
                low, high = f.metadata["range"]
                if not isinstance(value, (int, float)) or not np.isfinite(value) or not (
                        low - 1e-12 <= value <= high + 1e-12):
                    raise ValueError(f"{type(self).__name__}.{f.name} must be a number in "
                                     f"[{low}, {high}], got {value!r}")
                object.__setattr__(self, f.name, float(value))
            elif value not in f.metadata["choices"]:
                raise ValueError(f"{type(self).__name__}.{f.name} must be one of "
                                 f"{f.metadata['choices']}, got {value!r}")

    @classmethod
    def sample(cls: type[S], rng: np.random.Generator) -> S:
        """Every field drawn uniformly from its range (choices by their weights)."""
        values: dict[str, Any] = {}
        for f in dataclasses.fields(cls):
            if "range" in f.metadata:
                values[f.name] = float(rng.uniform(*f.metadata["range"]))
            else:
                options = f.metadata["choices"]
                weights = f.metadata.get("weights")
                p = None if weights is None else np.asarray(weights) / np.sum(weights)
                values[f.name] = str(options[rng.choice(len(options), p=p)])
        return cls(**values)

    @classmethod
    def from_dict(cls: type[S], values: Mapping[str, Any] | None) -> S:
        """Defaults overridden by ``values``; unknown keys are errors."""
        values = dict(values or {})
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = set(values) - known
        if unknown:
            raise ValueError(f"unknown {cls.garment_type} style parameter(s) {sorted(unknown)}; "
                             f"expected some of {sorted(known)}")
        return cls(**values)

    def as_dict(self) -> dict[str, float | str]:
        return dataclasses.asdict(self)

    @classmethod
    def describe(cls) -> list[tuple[str, str, str]]:
        """``(name, range or choices, meaning)`` per field, for the documentation."""
        rows = []
        for f in dataclasses.fields(cls):
            span = (f"{f.metadata['range'][0]:g} – {f.metadata['range'][1]:g}"
                    if "range" in f.metadata else " / ".join(f.metadata["choices"]))
            rows.append((f.name, span, f.metadata["doc"]))
        return rows
