"""Garment placement checks: is the garment given in the rest body's frame?

The model expects the garment rest mesh in the **rest body's frame**: metres, Z up, the
body facing −Y, draped around (not inside, not away from) the body in its T-pose. The
usual ways a user's file breaks that, each with a :class:`Finding`:

* ``units`` — the mesh is in centimetres or millimetres (its size is ~100× or ~1000×
  the body's); fixed by :func:`fix_placement` ``units="cm"|"mm"``.
* ``up_axis`` — the mesh is Y up (OBJ/glTF convention) while the body is Z up; fixed by
  ``up_axis="y"`` (``(x, y, z) ↦ (x, −z, y)``, a +90° turn about X).
* ``far_from_body`` — its bounding box misses the body's, or it floats well away from
  the body surface: a different origin (move it in a DCC tool).
* ``intersects_body`` — a large share of its vertices lie inside the rest body.

Pure numpy/scipy; array in, findings out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Plausible garment-to-body bounding-box diagonal ratios (a glove … a long coat).
PLAUSIBLE_RATIO = (0.05, 2.0)
#: Scale of each supported unit, in metres.
UNIT_SCALES = {"m": 1.0, "cm": 0.01, "mm": 0.001}
#: Bounding-box diagonal of an adult body (metres), used when no body is given.
TYPICAL_BODY_DIAGONAL = 1.9
#: Body bounding box margin (metres) within which the garment box must fall.
BOX_MARGIN = 0.05
#: Median garment-to-body distance (metres) above which the garment "floats" (a long
#: flared skirt on an adult body measures ~0.2).
FLOATING_DISTANCE = 0.3
#: Median distance (metres) from the body beyond which a garment as given is "far off"
#: for the up-axis rule (Z-up garments on their own body measured at most 9 cm).
FAR_AS_GIVEN = 0.12
#: How far (metres) a garment may reach above the top of the head (a hood, a hat's
#: brim) and below the soles; and the share of its vertices beyond that which marks it
#: as placed in another frame (CLOTH3D's starter kit: trousers in a world frame, feet
#: at z = 0, land around the head with the body's median distance of a loose garment).
BEYOND_HEIGHT = (0.10, 0.05)
BEYOND_FRACTION = 0.05
#: Depth (metres) below the body surface that counts as inside.
INSIDE_DEPTH = 0.005
#: Share of garment vertices inside the body that is reported (warning, error).
INSIDE_FRACTION = (0.05, 0.5)
#: Body surface samples for distance queries (~1 cm apart on an adult body).
SURFACE_SAMPLES = 20000
#: Y up → Z up: ``(x, y, z) ↦ (x, −z, y)`` (a +90° rotation about X).
Z_UP_FROM_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


@dataclass(frozen=True)
class Finding:
    """One placement problem.

    Attributes:
        code: ``"units"``, ``"up_axis"``, ``"far_from_body"`` or ``"intersects_body"``.
        severity: ``"error"`` (the animation would be meaningless) or ``"warning"``.
        message: one sentence with the measured numbers.
        fix: keyword arguments of :func:`fix_placement` that correct it (``{}`` when the
            fix needs a DCC tool, e.g. moving the garment).
    """

    code: str
    severity: str
    message: str
    fix: dict[str, str]

    def __str__(self) -> str:
        return f"{self.severity}: {self.message}"


def detect_units(pos: np.ndarray, body_vertices: np.ndarray | None = None) -> str | None:
    """The unit (``"m"``, ``"cm"``, ``"mm"``) that makes the garment's size plausible next
    to the body (or an adult body when ``body_vertices`` is None); ``None`` if none does.

    Shapes:
        pos ``(N, 3)``, body_vertices ``(N_b, 3)`` metres.
    """
    ratio = _diagonal(pos) / (TYPICAL_BODY_DIAGONAL if body_vertices is None
                              else _diagonal(body_vertices))
    for unit, scale in UNIT_SCALES.items():
        if PLAUSIBLE_RATIO[0] <= ratio * scale <= PLAUSIBLE_RATIO[1]:
            return unit
    return None


def detect_up_axis(pos: np.ndarray, body_vertices: np.ndarray,
                   body_faces: np.ndarray | None = None) -> str:
    """``"y"`` when the garment fits the body clearly better after turning it from Y up to
    Z up, else ``"z"``.

    "Fits better" compares the garment as given with the turned one on two measures: the
    share of vertices inside the body (needs ``body_faces``) and the median distance to
    the body. The turn wins when it removes intersections (over 2 points fewer inside)
    without moving the garment much further away (median within +25%), or when it at
    least halves a distance over 5 cm without adding intersections, or when it halves a
    distance over :data:`FAR_AS_GIVEN` (a garment made on another body). A garment turned
    about the body's origin (the pelvis, for most body models) stays near the body, so
    distance alone cannot tell; but worn the wrong way up it cuts through the body.

    Shapes:
        pos ``(N, 3)`` metres, body_vertices ``(N_b, 3)`` (rest body, Z up), body_faces
        ``(F_b, 3)``.
    """
    surface = _Surface(np.asarray(body_vertices, dtype=np.float64), body_faces)
    return _up_axis(np.asarray(pos, dtype=np.float64), surface)


def _up_axis(pos: np.ndarray, surface: _Surface) -> str:
    given_inside, given_distance = surface.fit(pos)
    turned_inside, turned_distance = surface.fit(pos @ Z_UP_FROM_Y_UP.T)
    fewer_intersections = (turned_inside < given_inside - 0.02
                           and turned_distance < 1.25 * given_distance)
    much_closer = (given_distance > 0.05 and turned_distance < 0.5 * given_distance
                   and turned_inside <= given_inside + 0.02)
    # A garment made on another body (SMPL, a mannequin) may intersect ours more once
    # turned, but as given it floats beside the body (median 16-35 cm on the real
    # garments measured, 2.5-9 cm for Z-up ones): far off as given, and at least twice as
    # close turned, is Y up whatever the intersections.
    far_as_given = given_distance > FAR_AS_GIVEN and turned_distance < 0.5 * given_distance
    return "y" if fewer_intersections or much_closer or far_as_given else "z"


def check_garment_placement(pos: np.ndarray, faces: np.ndarray, body_vertices: np.ndarray,
                            body_faces: np.ndarray) -> list[Finding]:
    """Find the common placement mistakes of a garment relative to the rest body.

    Units and up axis are checked first; distance and intersection are then measured on
    the garment with those fixes applied (they would be meaningless otherwise), and the
    messages say so.

    Args:
        pos: ``(N, 3)`` garment rest vertices as the user gave them.
        faces: ``(F, 3)`` garment triangles (validated for shape only).
        body_vertices: ``(N_b, 3)`` rest body vertices, metres, Z up.
        body_faces: ``(F_b, 3)`` body triangles, outward winding (a closed body).

    Returns:
        Findings, most fundamental first; empty when the garment looks well placed.

    Raises:
        ValueError: arrays of the wrong shape or with NaN/inf.
    """
    pos = _points(pos, "pos")
    body = _points(body_vertices, "body_vertices")
    faces = np.asarray(faces)
    body_faces = np.asarray(body_faces)
    for name, array, count in (("faces", faces, len(pos)), ("body_faces", body_faces,
                                                             len(body))):
        if array.ndim != 2 or array.shape[1] != 3 or (
                array.size and (array.min() < 0 or array.max() >= count)):
            raise ValueError(f"{name} must be (F, 3) indices into {count} vertices")
    surface = _Surface(body, body_faces)
    findings: list[Finding] = []
    fix: dict[str, str] = {}
    ratio = _diagonal(pos) / _diagonal(body)
    unit = detect_units(pos, body)
    if unit in ("cm", "mm"):
        findings.append(Finding(
            "units", "error",
            f"the garment is {ratio:.0f}× the body's size: it looks like it is in "
            f"{'centimetres' if unit == 'cm' else 'millimetres'}, the body is in metres",
            {"units": unit}))
        fix["units"] = unit
    elif unit is None:
        findings.append(Finding(
            "units", "error",
            f"the garment's bounding box is {ratio:.3g}× the body's, implausible in "
            f"metres, centimetres or millimetres: rescale it to metres", {}))
    scaled = pos * UNIT_SCALES.get(fix.get("units", "m"), 1.0)
    if _up_axis(scaled, surface) == "y":
        findings.append(Finding(
            "up_axis", "error",
            "the garment looks Y-up (it fits the body only after a +90° turn "
            "about X); the body is Z-up", {"up_axis": "y"}))
        fix["up_axis"] = "y"
    placed = scaled @ Z_UP_FROM_Y_UP.T if fix.get("up_axis") == "y" else scaled
    after = f" (after {_describe(fix)})" if fix else ""

    low, high = body.min(axis=0) - BOX_MARGIN, body.max(axis=0) + BOX_MARGIN
    garment_low, garment_high = placed.min(axis=0), placed.max(axis=0)
    offset = (garment_low + garment_high) / 2 - (body.min(axis=0) + body.max(axis=0)) / 2
    if (garment_high < low).any() or (garment_low > high).any():
        findings.append(Finding(
            "far_from_body", "error",
            f"the garment's bounding box does not overlap the body's{after}; its centre is "
            f"{np.linalg.norm(offset):.2f} m from the body's centre, offset (x, y, z) = "
            f"({offset[0]:+.2f}, {offset[1]:+.2f}, {offset[2]:+.2f}) m: move it onto the "
            f"rest body in its T-pose (--offset X Y Z, or --source-body with the body it "
            f"was made on)", {}))
        return findings
    body_bottom, body_top = body[:, 2].min(), body[:, 2].max()
    above = placed[:, 2] > body_top + BEYOND_HEIGHT[0]
    below = placed[:, 2] < body_bottom - BEYOND_HEIGHT[1]
    if np.mean(above | below) > BEYOND_FRACTION:
        where, reach = (("above the top of the body's head", placed[:, 2].max() - body_top)
                        if above.sum() >= below.sum() else
                        ("below the body's soles", body_bottom - placed[:, 2].min()))
        findings.append(Finding(
            "beyond_body", "error",
            f"{100 * np.mean(above | below):.0f}% of the garment's vertices are {where} "
            f"(by up to {reach:.2f} m){after}: it looks placed in another frame (e.g. a "
            f"world frame with the feet at z = 0); move it onto the rest body in its "
            f"T-pose (--offset X Y Z, or --source-body with the body it was made on)", {}))
        return findings
    distance = float(np.median(surface.distance(placed)))
    if distance > FLOATING_DISTANCE:
        findings.append(Finding(
            "far_from_body", "warning",
            f"the garment floats {distance:.2f} m (median) from the body surface{after}; "
            f"centre offset ({offset[0]:+.2f}, {offset[1]:+.2f}, {offset[2]:+.2f}) m", {}))
    inside = float(np.mean(surface.signed_distance(placed) < -INSIDE_DEPTH))
    if inside > INSIDE_FRACTION[0]:
        severity = "error" if inside > INSIDE_FRACTION[1] else "warning"
        findings.append(Finding(
            "intersects_body", severity,
            f"{100 * inside:.0f}% of the garment's vertices are more than "
            f"{1000 * INSIDE_DEPTH:.0f} mm inside the rest body{after}: it must be draped "
            f"around the body in its T-pose", {}))
    return findings


def inside_fraction(pos: np.ndarray, body_vertices: np.ndarray, body_faces: np.ndarray,
                    depth: float = INSIDE_DEPTH) -> float:
    """Share of ``pos`` more than ``depth`` metres inside the closed body.

    The sign comes from the outward normal of the nearest point of a dense sampling of
    the body surface (faces wound inwards are detected by the signed volume and
    flipped): a fast estimate, exact for convex patches and good to the sample spacing
    (about 1 cm on an adult body) elsewhere.
    """
    surface = _Surface(np.asarray(body_vertices, dtype=np.float64), body_faces)
    return float(np.mean(surface.signed_distance(np.asarray(pos, dtype=np.float64)) < -depth))


def fix_placement(pos: np.ndarray, units: str = "auto", up_axis: str = "z",
                  body_vertices: np.ndarray | None = None,
                  body_faces: np.ndarray | None = None, scale: float | None = None,
                  offset: np.ndarray | None = None) -> tuple[np.ndarray, str]:
    """Rescale to metres, turn to Z up, then move by an explicit offset.

    Args:
        pos: ``(N, 3)`` garment vertices as given.
        units: ``"m"``, ``"cm"``, ``"mm"``, or ``"auto"`` (:func:`detect_units`, next to
            ``body_vertices`` when given; an implausible size is left unscaled).
        up_axis: the garment's up axis, ``"z"`` (nothing to do), ``"y"`` (turned to Z up),
            or ``"auto"`` (:func:`detect_up_axis`; needs ``body_vertices``).
        body_vertices: ``(N_b, 3)`` rest body, for the automatic choices.
        body_faces: its ``(F_b, 3)`` faces (optional).
        scale: metres per file unit, replacing the unit choice (``units`` must then be
            ``"auto"``): for a mesh whose units no rule can guess.
        offset: ``(3,)`` metres added after the scale and the turn (in the rest body's
            frame, Z up): for a garment made with another origin, e.g. feet at zero.

    Returns:
        ``(pos, message)``: corrected float64 positions (same vertex order) and what was
        applied, e.g. ``"scaled centimetres to metres (×0.01); turned Y-up to Z-up"``.

    Raises:
        ValueError: unknown option, bad ``pos``, or ``up_axis="auto"`` without a body.
    """
    pos = _points(pos, "pos")
    if units not in (*UNIT_SCALES, "auto"):
        raise ValueError(f"units must be 'auto', 'm', 'cm' or 'mm', got {units!r}")
    if up_axis not in ("z", "y", "auto"):
        raise ValueError(f"up_axis must be 'z', 'y' or 'auto', got {up_axis!r}")
    body = None if body_vertices is None else _points(body_vertices, "body_vertices")
    applied: dict[str, str] = {}
    if scale is not None:
        if units != "auto":
            raise ValueError(f"give either a scale or units, not both (units {units!r})")
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"scale must be a finite number > 0, got {scale}")
        pos = pos * scale
        applied["scale"] = f"{scale:g}"
        units = "m"
    if units == "auto":
        units = detect_units(pos, body) or "m"
    if units != "m":
        pos = pos * UNIT_SCALES[units]
        applied["units"] = units
    if up_axis == "auto":
        if body is None:
            raise ValueError("up_axis='auto' needs body_vertices")
        up_axis = detect_up_axis(pos, body, body_faces)
    if up_axis == "y":
        pos = pos @ Z_UP_FROM_Y_UP.T
        applied["up_axis"] = "y"
    if offset is not None:
        offset = np.asarray(offset, dtype=np.float64)
        if offset.shape != (3,) or not np.isfinite(offset).all():
            raise ValueError(f"offset must be 3 finite numbers (metres), got {offset.tolist()}")
        pos = pos + offset
        applied["offset"] = "({:+.3f}, {:+.3f}, {:+.3f})".format(*offset)
    return pos, _describe(applied) if applied else "kept as given (metres, Z up)"


def _describe(fix: dict[str, str]) -> str:
    parts = []
    if "scale" in fix:
        parts.append(f"scaled by {fix['scale']} (given)")
    if "units" in fix:
        name = {"cm": "centimetres", "mm": "millimetres"}[fix["units"]]
        parts.append(f"scaled {name} to metres (×{UNIT_SCALES[fix['units']]:g})")
    if fix.get("up_axis") == "y":
        parts.append("turned Y-up to Z-up ((x, y, z) → (x, −z, y))")
    if "offset" in fix:
        parts.append(f"moved by {fix['offset']} m (given)")
    return "; ".join(parts)


def _points(array: np.ndarray, name: str) -> np.ndarray:
    array = np.asarray(array, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 3 or len(array) == 0:
        raise ValueError(f"{name} must be (N, 3) with N ≥ 1, got {array.shape}")
    if not np.isfinite(array).all():
        raise ValueError(f"{name} contains NaN or inf")
    return array


def _diagonal(pos: np.ndarray) -> float:
    pos = np.asarray(pos, dtype=np.float64)
    return max(float(np.linalg.norm(pos.max(axis=0) - pos.min(axis=0))), 1e-12)


class _Surface:
    """Nearest-point queries against a body: its vertices plus area-uniform samples of its
    faces (coarse meshes have long faces far from any vertex), each with an outward
    normal."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray | None,
                 samples: int = SURFACE_SAMPLES) -> None:
        from scipy.spatial import cKDTree

        from gnngarment.geometry.normals import face_normals, vertex_normals
        from gnngarment.geometry.surface_sampling import surface_samples

        if faces is None:
            self.points, self.normals = vertices, None
        else:
            faces = np.asarray(faces, dtype=np.int64)
            flip = -1.0 if _signed_volume(vertices, faces) < 0 else 1.0
            sampled, chosen = surface_samples(vertices, faces, samples)
            self.points = np.concatenate([vertices, sampled])
            self.normals = flip * np.concatenate([vertex_normals(vertices, faces),
                                                  face_normals(vertices, faces[chosen])])
        self.tree = cKDTree(self.points)

    def distance(self, pos: np.ndarray) -> np.ndarray:
        return self.tree.query(pos)[0]

    def fit(self, pos: np.ndarray) -> tuple[float, float]:
        """(share of ``pos`` deeper than :data:`INSIDE_DEPTH` inside — 0 without faces,
        median distance to the surface)."""
        if self.normals is None:
            return 0.0, float(np.median(self.distance(pos)))
        signed = self.signed_distance(pos)
        return float(np.mean(signed < -INSIDE_DEPTH)), float(np.median(np.abs(signed)))

    def signed_distance(self, pos: np.ndarray) -> np.ndarray:
        """Distance to the nearest surface point, negative inside (needs faces)."""
        distance, nearest = self.tree.query(pos)
        side = np.einsum("na,na->n", pos - self.points[nearest], self.normals[nearest])
        return np.where(side < 0, -distance, distance)


def _signed_volume(pos: np.ndarray, faces: np.ndarray) -> float:
    corners = pos[faces]
    return float(np.einsum("fa,fa->f", corners[:, 0],
                           np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0)
