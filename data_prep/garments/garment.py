"""The procedural garment set: one entry point per garment, and the seeded sampler.

``make_garment(body, "tshirt", style, target_vertices=3000, seed=0)`` builds one garment
around a body; ``sample_garment(body, rng)`` draws a type, a style and a resolution and
retries (another style) in the rare case a design cannot be meshed cleanly. Every
returned garment has passed :func:`~data_prep.garments.checks.garment_problems`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from data_prep.garments.body_frame import BodyFrame
from data_prep.garments.dress import DressStyle, dress_outline
from data_prep.garments.errors import PatternError
from data_prep.garments.jumpsuit import JumpsuitStyle, jumpsuit_outline
from data_prep.garments.mesher import mesh_design
from data_prep.garments.outline import GarmentOutline
from data_prep.garments.parts import CLEARANCE
from data_prep.garments.skirt import SkirtStyle, skirt_outline
from data_prep.garments.style import Style
from data_prep.garments.top import TopStyle, top_outline
from data_prep.garments.trousers import TrousersStyle, trousers_outline
from data_prep.garments.tshirt import TShirtStyle, tshirt_outline

#: garment type → (style class, outline function)
GARMENT_TYPES: dict[str, tuple[type[Style], Callable[[BodyFrame, Any], GarmentOutline]]] = {
    "skirt": (SkirtStyle, skirt_outline),
    "trousers": (TrousersStyle, trousers_outline),
    "tshirt": (TShirtStyle, tshirt_outline),
    "top": (TopStyle, top_outline),
    "dress": (DressStyle, dress_outline),
    "jumpsuit": (JumpsuitStyle, jumpsuit_outline),
}

#: Default range of target vertex counts drawn by the sampler (log-uniform).
DEFAULT_RESOLUTION = (1000, 5000)
MAX_VERTICES = 15000


class GarmentError(ValueError):
    """A garment could not be built cleanly for this body and style."""


@dataclasses.dataclass
class Garment:
    """A rest garment mesh around a body.

    Attributes:
        name: unique, readable id (``"<type>_<seed>"``).
        garment_type: one of :data:`GARMENT_TYPES`.
        style: the style parameters (metres, fractions, choices) and ``target_vertices``.
        pos: ``(N, 3)`` float64 vertex positions, metres, in the body's frame.
        faces: ``(F, 3)`` int64 triangles, outward-facing.
        pin_candidates: ``(L,)`` vertex indices of the top opening's boundary loop, in
            loop order (a skirt's or trousers' waistband; the neckline of a shirt).
        openings: every opening's boundary loop by name (``waist``, ``hem``, ``neck``,
            ``cuff_L``, ``armhole_R``, ``leg_L``, ``top`` …), each ``(L_i,)`` in order.
    """

    name: str
    garment_type: str
    style: dict[str, Any]
    pos: np.ndarray
    faces: np.ndarray
    pin_candidates: np.ndarray
    openings: dict[str, np.ndarray]

    @property
    def num_vertices(self) -> int:
        return len(self.pos)


def make_garment(body: BodyFrame, garment_type: str,
                 style: Style | Mapping[str, Any] | None = None, *,
                 target_vertices: int = 3000, seed: int = 0, name: str | None = None,
                 check: bool = True, retries: int = 2) -> Garment:
    """Build one garment around ``body``.

    Args:
        body: the rest body (vertices, faces, 24 joints).
        garment_type: one of :data:`GARMENT_TYPES`.
        style: the type's style dataclass, or a mapping overriding its defaults.
        target_vertices: approximate vertex count (300 … 15000; within a few %).
        seed: seed of the irregular triangulation (interior points of the pattern).
        name: defaults to ``"<type>_<seed>"``.
        check: validate the result (:func:`~data_prep.garments.checks.garment_problems`)
            and raise :class:`GarmentError` if it fails.
        retries: if the mesh fails validation, try again this many times with another
            triangulation (seeds ``seed + 1`` …); the design itself is kept.

    Raises:
        ValueError: unknown type, bad style values or resolution.
        GarmentError: this design cannot be meshed cleanly around this body.
    """
    if garment_type not in GARMENT_TYPES:
        raise ValueError(f"unknown garment type {garment_type!r}; expected one of "
                         f"{sorted(GARMENT_TYPES)}")
    if not 300 <= int(target_vertices) <= MAX_VERTICES:
        raise ValueError(f"target_vertices must be in [300, {MAX_VERTICES}], got {target_vertices}")
    style_class, outline_of = GARMENT_TYPES[garment_type]
    if not isinstance(style, style_class):
        style = style_class.from_dict(style)  # type: ignore[arg-type]
    try:
        outline = outline_of(body, style)
    except PatternError as error:
        raise GarmentError(f"{garment_type}: {error}") from error
    problems: list[str] = []
    for attempt in range(retries + 1):
        try:
            mesh = mesh_design(outline.design, body.distance, int(target_vertices),
                               np.random.default_rng(seed + attempt), clearance=CLEARANCE)
        except PatternError as error:
            problems = [str(error)]
            continue
        if outline.top not in mesh.loops:
            problems = [f"no {outline.top!r} opening (got {sorted(mesh.loops)})"]
            continue
        garment = Garment(
            name=name or f"{garment_type}_{seed}", garment_type=garment_type,
            style={**style.as_dict(), "target_vertices": int(target_vertices)},
            pos=mesh.pos, faces=mesh.faces, pin_candidates=mesh.loops[outline.top],
            openings=mesh.loops)
        if not check:
            return garment
        from data_prep.garments.checks import garment_problems

        problems = garment_problems(garment, body, expected_openings=outline.loops,
                                    clearance=0.5 * CLEARANCE)
        if not problems:
            return garment
    raise GarmentError(f"{name or garment_type}: " + "; ".join(problems))


def sample_garment(body: BodyFrame, rng: np.random.Generator | int | None = None,
                   garment_type: str | None = None, *,
                   resolution: tuple[int, int] = DEFAULT_RESOLUTION,
                   max_attempts: int = 10) -> Garment:
    """Draw one random garment around ``body``.

    The type is uniform over :data:`GARMENT_TYPES` (unless given), every style parameter
    uniform in its range, the target vertex count log-uniform in ``resolution``. A
    design that cannot be meshed cleanly is replaced by a new style of the same type
    (up to ``max_attempts``; about 1 % of designs need that on T-pose bodies). Same body
    and seed → same garment.

    Args:
        body: the rest body.
        rng: a ``numpy`` generator or a seed.
    """
    rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    if garment_type is not None and garment_type not in GARMENT_TYPES:
        raise ValueError(f"unknown garment type {garment_type!r}; expected one of "
                         f"{sorted(GARMENT_TYPES)}")
    kind = garment_type or str(rng.choice(sorted(GARMENT_TYPES)))
    errors = []
    for _ in range(max_attempts):
        style = GARMENT_TYPES[kind][0].sample(rng)
        low, high = resolution
        target = round(float(np.exp(rng.uniform(np.log(low), np.log(high)))))
        seed = int(rng.integers(2**31))
        try:
            return make_garment(body, kind, style, target_vertices=target, seed=seed)
        except GarmentError as error:
            errors.append(str(error))
    raise GarmentError(f"no valid {kind} in {max_attempts} attempts: " + " | ".join(errors))
