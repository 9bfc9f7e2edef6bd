"""Is a rest template consistent with its point-cache frames?

A ``.pc16`` frame ``t`` is the garment posed by ``poses[t]`` about the root joint
(:mod:`data_prep.cloth3d.frames`), and the rest OBJ is the same garment in CLOTH3D's
rest pose, whose root rotation is +90° about x (:data:`REST_ROOT_ROTATION`). Undoing
frame t's root rotation relative to the rest root therefore brings the frame back over
the rest template: what is left is the motion of the limbs and the cloth, not a turn. A
template stored in another orientation (e.g. turned by ``zrot``) or place shows up as a
turn or a distance that no frame explains. Measured on the real sequence 00006: fitted
turn −4° (Top) / +5° (Trousers), median distance 4–6 cm; the same templates turned by
−zrot: +157° / +166° and 32–35 cm (``docs/cloth3d.md``).

Only numpy and scipy: no body model is needed, just the root's axis-angle per frame.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: CLOTH3D's rest-pose root rotation (axis-angle, radians): SMPL's Y-up body turned Z-up.
REST_ROOT_ROTATION = np.array([np.pi / 2, 0.0, 0.0])
#: Most z-turn (radians) between the rest template and its un-rooted frames, fitted over
#: all frames, for the two to be consistent: 20°, 4× the turn measured on real data.
MAX_TURN = np.radians(20.0)
#: Most median vertex distance (metres) between the rest template and its un-rooted
#: frames (median over frames): measured 4–6 cm on real data, 32–35 cm when turned.
MAX_DISTANCE = 0.15


class RestAlignment(NamedTuple):
    """How well a rest template matches its frames once their root rotation is undone.

    Attributes:
        turn: ``(T,)`` radians in (−π, π], the rotation about +z through the root that
            best maps the rest template onto un-rooted frame t (least squares in xy).
        distance: ``(T,)`` metres, median vertex distance between the rest template and
            un-rooted frame t (vertices correspond by index).
        fitted_turn: radians in (−π, π], the one z-turn that best maps the rest template
            onto all un-rooted frames together.
    """

    turn: np.ndarray
    distance: np.ndarray
    fitted_turn: float

    @property
    def median_distance(self) -> float:
        """Median over frames of :attr:`distance`, metres."""
        return float(np.median(self.distance)) if len(self.distance) else 0.0

    def problem(self, max_turn: float = MAX_TURN, max_distance: float = MAX_DISTANCE
                ) -> str | None:
        """``None`` when consistent, else one line saying what is off (for reports)."""
        if abs(self.fitted_turn) > max_turn:
            return (f"rest template is turned {np.degrees(self.fitted_turn):+.0f}° about z "
                    f"from its frames once their root rotation is undone (at most "
                    f"{np.degrees(max_turn):.0f}° allowed): the OBJ is not in the rest frame")
        if self.median_distance > max_distance:
            return (f"rest template is {self.median_distance:.2f} m (median) from its frames "
                    f"once their root rotation is undone (at most {max_distance:.2f} m "
                    f"allowed): the OBJ is not in the rest frame")
        return None


def unroot_frames(frames: np.ndarray, root_rotations: np.ndarray) -> np.ndarray:
    """Undo each frame's root rotation, relative to the rest pose's root:
    ``x ↦ R_rest · R_tᵀ · x`` (rotation about the origin, where the root is).

    Shapes:
        frames ``(T, N, 3)`` metres in the cache frame, root_rotations ``(T, 3)``
        axis-angle radians (``poses[:, :3]``) → ``(T, N, 3)`` float64.

    Raises:
        ValueError: shapes that do not match.
    """
    from scipy.spatial.transform import Rotation

    frames = np.asarray(frames, dtype=np.float64)
    root_rotations = np.asarray(root_rotations, dtype=np.float64)
    if frames.ndim != 3 or frames.shape[-1] != 3:
        raise ValueError(f"frames have shape {frames.shape}, expected (T, N, 3)")
    if root_rotations.shape != (len(frames), 3):
        raise ValueError(f"root_rotations have shape {root_rotations.shape}, expected "
                         f"(T, 3) = ({len(frames)}, 3)")
    undo = (Rotation.from_rotvec(REST_ROOT_ROTATION)
            * Rotation.from_rotvec(root_rotations).inv()).as_matrix()  # (T, 3, 3)
    return np.einsum("tab,tnb->tna", undo, frames)


def rest_alignment(rest_pos: np.ndarray, frames: np.ndarray,
                   root_rotations: np.ndarray) -> RestAlignment:
    """Compare a rest template with every frame, root rotation undone.

    Shapes:
        rest_pos ``(N, 3)`` metres, root at the origin; frames ``(T, N, 3)`` metres in
        the cache frame; root_rotations ``(T, 3)`` axis-angle radians.

    Raises:
        ValueError: shapes that do not match.
    """
    rest_pos = np.asarray(rest_pos, dtype=np.float64)
    if rest_pos.ndim != 2 or rest_pos.shape[1] != 3:
        raise ValueError(f"rest_pos has shape {rest_pos.shape}, expected (N, 3)")
    unrooted = unroot_frames(frames, root_rotations)
    if unrooted.shape[1] != len(rest_pos):
        raise ValueError(f"frames have {unrooted.shape[1]} vertices but rest_pos has "
                         f"{len(rest_pos)}")
    # Least-squares rotation about z taking a onto b: angle of Σ (a·b, (a×b)_z) in xy.
    cross = (rest_pos[None, :, 0] * unrooted[..., 1]
             - rest_pos[None, :, 1] * unrooted[..., 0]).sum(axis=1)
    dot = (rest_pos[None, :, :2] * unrooted[..., :2]).sum(axis=(1, 2))
    distance = np.median(np.linalg.norm(unrooted - rest_pos[None], axis=-1), axis=1)
    return RestAlignment(turn=np.arctan2(cross, dot), distance=distance,
                         fitted_turn=float(np.arctan2(cross.sum(), dot.sum())))
