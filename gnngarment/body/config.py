"""Settings of the body package (defaults mirrored in ``configs/body.yaml``)."""

from __future__ import annotations

import dataclasses
from pathlib import Path


@dataclasses.dataclass
class BodyConfig:
    """Which body model to use.

    The body-vertex count N_b' and the motion window m are the model's
    (``ModelConfig.body_vertices``, ``ModelConfig.window``; the cache records the former),
    the frame rate is the dataset's or the animate call's: none of them lives here.

    Attributes:
        model: ``"anny"`` (default, ships with its wheel) or ``"smpl"`` (user file).
        smpl_model_path: SMPL ``.pkl``/``.npz`` file (or folder of ``SMPL_<GENDER>.pkl``),
            used when ``model == "smpl"``.
        smpl_gender: ``neutral``, ``male`` or ``female`` (picks the file in a folder).
        anny_rest_pose: ``"tpose"`` (the canonical rest pose, arms along ±X) or
            ``"native"`` (Anny's own A-pose; mocap meant for a T-pose then looks wrong).
    """

    model: str = "anny"
    smpl_model_path: str = ""
    smpl_gender: str = "neutral"
    anny_rest_pose: str = "tpose"


def load_body_config(path: str | Path | None = None) -> BodyConfig:
    """``configs/body.yaml`` (or ``path``) merged strictly onto :class:`BodyConfig`."""
    from gnngarment.config import load_config

    if path is None:
        return BodyConfig()
    return load_config(path, BodyConfig)
