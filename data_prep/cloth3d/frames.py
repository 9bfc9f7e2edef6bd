"""CLOTH3D frame conventions as pure array functions, shared by garments and bodies.

CLOTH3D stores each sequence in three frames (``R_z(a)`` is the rotation by ``a``
radians about +z, Z-up, metres):

- **rest** — the ``<Garment>.obj`` rest mesh is the garment on the rest body (root
  rotated +90° about x so the body is Z-up, facing −y), root joint at the origin. It is
  stored *canonical*: neither ``trans`` nor ``zrot`` is applied to it.
- **cache frame** — a ``.pc16`` frame ``t`` lies in the frame of
  ``SMPL(pose_t, shape, trans=0) − J_0(shape)``: the posed body with its root joint
  (pelvis) at the origin, before the sequence's translation and z-rotation. Undoing the
  root rotation of frame t brings it back over the rest mesh
  (:mod:`data_prep.cloth3d.rest_alignment`).
- **world** — ``world = R_z(zrot) · (x + trans_t)``: add the root translation of frame
  ``t``, then rotate the whole sequence about +z by ``zrot`` (``info.mat``).

Measured on the real sequence 00006 (``docs/cloth3d.md``, tests in
``tests/data_prep/test_cloth3d_real_sample.py``): the rest OBJs are mirror-symmetric about
x = 0 (median gap 5–8 mm; turned by −zrot 18–31 mm); un-rooted frames lie over the rest
OBJ with no turn (−4°/+5°); frame centroids stay within 4 cm of the root while trans
moves 2.3 m; the root faces the way trans travels (13°), so trans is added before zrot.
Not measurable without an SMPL model (not shipped): the exact rest pose of the legs
(DESIGN.md: hips ±0.15 rad about z; the Trousers' legs do splay about 0.15 m per metre).

The functions take any point set with a leading frame axis, so the body side uses the
same transforms: posed SMPL vertices ``(T, 6890, 3)`` or joints ``(T, 24, 3)`` computed
with ``trans = 0`` and minus ``J_0`` are in the cache frame, and :func:`world_transform`
left-multiplies the 24 global joint transforms ``(T, 24, 4, 4)`` into the world.
"""

from __future__ import annotations

import numpy as np


def z_rotation(zrot: float) -> np.ndarray:
    """``R_z(zrot)``: the ``(3, 3)`` float64 rotation by ``zrot`` radians about +z."""
    c, s = np.cos(zrot), np.sin(zrot)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _check_frames(points: np.ndarray, trans: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    points = np.asarray(points)
    trans = np.asarray(trans)
    if points.ndim < 2 or points.shape[-1] != 3:
        raise ValueError(f"points have shape {points.shape}, expected (T, ..., 3)")
    if trans.shape != (points.shape[0], 3):
        raise ValueError(f"trans has shape {trans.shape}, expected (T, 3) = "
                         f"({points.shape[0]}, 3) to match points {points.shape}")
    dtype = np.result_type(points.dtype, np.float32)  # float32 stays float32
    # trans_t broadcasts over every axis between the frame axis and xyz.
    trans = trans.reshape((points.shape[0],) + (1,) * (points.ndim - 2) + (3,))
    return points.astype(dtype, copy=False), trans.astype(dtype, copy=False)


def to_world(points: np.ndarray, trans: np.ndarray, zrot: float) -> np.ndarray:
    """Cache frame → world: ``R_z(zrot) · (x + trans_t)``.

    Shapes:
        points ``(T, ..., 3)`` (e.g. garment ``(T, N, 3)``, joints ``(T, 24, 3)``),
        trans ``(T, 3)`` metres, zrot radians → ``(T, ..., 3)``, float32 if points are.
    """
    points, trans = _check_frames(points, trans)
    rotation = z_rotation(zrot).astype(points.dtype)
    return (points + trans) @ rotation.T


def from_world(points: np.ndarray, trans: np.ndarray, zrot: float) -> np.ndarray:
    """World → cache frame, the inverse of :func:`to_world`: ``R_z(−zrot) · x − trans_t``.

    Shapes:
        points ``(T, ..., 3)``, trans ``(T, 3)`` metres, zrot radians → ``(T, ..., 3)``.
    """
    points, trans = _check_frames(points, trans)
    rotation = z_rotation(zrot).astype(points.dtype)
    return points @ rotation - trans  # x @ R == (Rᵀ x) row-wise, and Rᵀ = R_z(−zrot)


def world_transform(trans: np.ndarray, zrot: float) -> np.ndarray:
    """Homogeneous cache-frame → world transforms, one per frame.

    ``W_t = [[R, R·trans_t], [0, 1]]`` with ``R = R_z(zrot)``, so ``W_t @ [x; 1]`` equals
    :func:`to_world` and ``W_t @ G_t`` moves a rigid transform ``G_t`` (e.g. a joint's
    global transform from SMPL posed with ``trans = 0`` and translated by ``−J_0``)
    into the world.

    Shapes:
        trans ``(T, 3)`` metres, zrot radians → ``(T, 4, 4)`` float64.
    """
    trans = np.asarray(trans, dtype=np.float64)
    if trans.ndim != 2 or trans.shape[1] != 3:
        raise ValueError(f"trans has shape {trans.shape}, expected (T, 3)")
    rotation = z_rotation(zrot)
    out = np.zeros((len(trans), 4, 4))
    out[:, :3, :3] = rotation
    out[:, :3, 3] = trans @ rotation.T
    out[:, 3, 3] = 1.0
    return out
