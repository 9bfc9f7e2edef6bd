"""SMPL from a user-supplied model file, through ``smplx``'s loader and LBS.

The SMPL licence forbids shipping the model: register at https://smpl.is.tue.mpg.de
and pass the ``.pkl`` (``SMPL_NEUTRAL.pkl``, ``basicmodel_m_lbs_10_207_0_v1.1.0.pkl``…)
or ``.npz`` file, or a folder holding ``SMPL_<GENDER>.pkl``. The body is presented in the
canonical frame (Z up: SMPL's Y-up vertices turned by ``C = Rx(+90°)``); SMPL's zero pose
is already a T-pose. Shape = 10 betas ``(10,)``.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Any

import numpy as np
import torch

from gnngarment.body.body_model import BodyModel, PosedBody, RestBody
from gnngarment.body.motion import Motion
from gnngarment.body.rotations import axis_angle_to_matrix
from gnngarment.body.skeleton import NUM_JOINTS, forward_kinematics
from gnngarment.body.smpl_motion import SMPL_TO_CANONICAL

NUM_BETAS = 10
SMPL_DOWNLOAD_HINT = (
    "the SMPL model cannot be shipped (licence); download it from https://smpl.is.tue.mpg.de "
    "(SMPL for Python, v1.1.0) and pass the .pkl/.npz file or its folder"
)


class SMPLModelError(FileNotFoundError):
    """The SMPL model file is missing or unreadable."""


def resolve_smpl_path(path: str | Path, gender: str = "neutral") -> Path:
    """The model file: ``path`` itself, or ``SMPL_<GENDER>.pkl|npz`` inside a folder."""
    if gender not in ("neutral", "male", "female"):
        raise ValueError(f"SMPL gender must be neutral, male or female, got {gender!r}")
    if not str(path):
        raise SMPLModelError(f"no SMPL model file given: {SMPL_DOWNLOAD_HINT}")
    path = Path(path).expanduser()
    if path.is_dir():
        for ext in ("pkl", "npz"):
            candidate = path / f"SMPL_{gender.upper()}.{ext}"
            if candidate.is_file():
                return candidate
        raise SMPLModelError(
            f"{path}: no SMPL_{gender.upper()}.pkl/.npz here; {SMPL_DOWNLOAD_HINT}"
        )
    if not path.is_file():
        raise SMPLModelError(f"{path}: SMPL model file not found; {SMPL_DOWNLOAD_HINT}")
    if path.suffix.lower() not in (".pkl", ".npz"):
        raise SMPLModelError(f"{path}: expected a .pkl or .npz SMPL model file")
    return path


def _read_npz_without_code(path: Path) -> dict[str, np.ndarray]:
    """Every array of an SMPL ``.npz``, refusing pickled objects: unpickling an untrusted
    file can run code (a ``v_template`` holding a pickle ran ``os.system``), and SMPL's
    arrays are all plain numbers and strings."""
    import zipfile

    if not zipfile.is_zipfile(path):  # np.load would take any other file for a pickle
        raise SMPLModelError(f"{path}: not an .npz archive (expected the SMPL model's arrays)")
    try:
        with np.load(path, allow_pickle=False) as archive:
            return {name: archive[name] for name in archive.files}
    except ValueError as error:
        if "allow_pickle" in str(error):
            raise SMPLModelError(
                f"{path}: holds pickled Python objects, which are refused (loading them "
                "could run code); convert it to plain arrays or pass the official .pkl "
                "from a trusted source") from error
        raise


class SMPLBodyModel(BodyModel):
    """SMPL behind the :class:`BodyModel` interface; shape = betas ``(10,)``.

    Args:
        model_path: ``.pkl``/``.npz`` file or folder (see module docstring).
        gender: ``neutral``, ``male`` or ``female`` (file choice inside a folder).
    """

    name = "smpl"

    def __init__(self, model_path: str | Path, gender: str = "neutral") -> None:
        try:
            import smplx
            from smplx.utils import Struct
        except ImportError as error:  # pragma: no cover - declared dependency
            raise ImportError("the SMPL body model needs 'smplx': pip install smplx") from error
        self.path = resolve_smpl_path(model_path, gender)
        try:
            # smplx prints a notice about 10-beta models on stdout; keep our output clean.
            with contextlib.redirect_stdout(io.StringIO()):
                if self.path.suffix.lower() == ".npz":
                    data = _read_npz_without_code(self.path)
                    self.smpl = smplx.SMPL(
                        str(self.path), data_struct=Struct(**data), gender=gender
                    )
                else:
                    self.smpl = smplx.SMPL(str(self.path), gender=gender)
        except SMPLModelError:
            raise
        except Exception as error:
            raise SMPLModelError(f"{self.path}: not a readable SMPL model ({error})") from error
        if int(self.smpl.J_regressor.shape[0]) != NUM_JOINTS:
            raise SMPLModelError(
                f"{self.path}: expected {NUM_JOINTS} joints, got {self.smpl.J_regressor.shape[0]}"
            )
        self._faces = np.asarray(self.smpl.faces, dtype=np.int64)
        self._C = torch.as_tensor(SMPL_TO_CANONICAL, dtype=torch.float32)

    @property
    def faces(self) -> np.ndarray:
        return self._faces

    def default_shape(self) -> torch.Tensor:
        return torch.zeros(NUM_BETAS)

    def parse_shape(self, spec: Any) -> torch.Tensor:
        """``None``/``"mean"`` (zeros), a sequence of ≤ 10 betas, or a ``.npy``/``.txt`` file."""
        if spec is None or (isinstance(spec, str) and spec in ("mean", "average")):
            return self.default_shape()
        if isinstance(spec, (str, Path)):
            path = Path(spec)
            if not path.is_file():
                raise ValueError(f"{path}: SMPL betas file not found (or use 'mean')")
            values = np.load(path) if path.suffix == ".npy" else np.loadtxt(path)
        else:
            values = np.asarray(spec)
        values = np.asarray(values, dtype=np.float64).reshape(-1)
        if values.size > NUM_BETAS or not np.all(np.isfinite(values)):
            raise ValueError(f"SMPL shape must be ≤ {NUM_BETAS} finite betas, got {values.size}")
        betas = torch.zeros(NUM_BETAS)
        betas[: values.size] = torch.as_tensor(values, dtype=torch.float32)
        return betas

    def _shaped(self, betas: torch.Tensor | None) -> tuple[torch.Tensor, torch.Tensor]:
        """SMPL-frame shaped template ``(N, 3)`` and joints ``(24, 3)``."""
        from smplx.lbs import blend_shapes, vertices2joints

        betas = self.parse_shape(betas) if not torch.is_tensor(betas) else betas
        betas = betas.reshape(1, -1)[:, : self.smpl.shapedirs.shape[-1]].float()
        v_shaped = self.smpl.v_template[None] + blend_shapes(betas, self.smpl.shapedirs)
        joints = vertices2joints(self.smpl.J_regressor, v_shaped)
        return v_shaped[0], joints[0]

    def skinning_weights(self) -> np.ndarray:
        """SMPL's ``lbs_weights`` ``(6890, 24)`` float32."""
        return self.smpl.lbs_weights.detach().cpu().numpy().astype(np.float32)

    def rest(self, shape: Any = None) -> RestBody:
        with torch.no_grad():
            vertices, joints = self._shaped(shape)
        return RestBody(vertices=vertices @ self._C.T, faces=self._faces, joints=joints @ self._C.T)

    def pose(self, motion: Motion, shape: Any = None) -> PosedBody:
        """Posed vertices ``(T, N, 3)`` (with SMPL's pose correctives) and transforms."""
        from smplx.lbs import lbs

        rotations, translation = motion.to_torch(torch.float32)
        count = motion.num_frames
        betas = self.parse_shape(shape) if not torch.is_tensor(shape) else shape
        rest = self.rest(betas)
        transforms, joints = forward_kinematics(rotations, rest.joints, translation)
        # The same rotations in SMPL's Y-up axes: R_smpl = Cᵀ R C for every joint.
        C = self._C
        smpl_mats = C.T @ axis_angle_to_matrix(rotations) @ C
        with torch.no_grad():
            vertices, _ = lbs(
                betas.reshape(1, -1).float().expand(count, -1),
                smpl_mats,
                self.smpl.v_template,
                self.smpl.shapedirs,
                self.smpl.posedirs,
                self.smpl.J_regressor,
                self.smpl.parents,
                self.smpl.lbs_weights,
                pose2rot=False,
            )
        vertices = vertices @ C.T + translation[:, None, :]
        return PosedBody(vertices=vertices, joint_transforms=transforms, joints=joints)
