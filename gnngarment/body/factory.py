"""Build the configured body model."""

from __future__ import annotations

from gnngarment.body.body_model import BodyModel
from gnngarment.body.config import BodyConfig


def create_body_model(config: BodyConfig | None = None) -> BodyModel:
    """The body model named by ``config.model`` (``anny`` default, or ``smpl``)."""
    config = config or BodyConfig()
    if config.model == "anny":
        from gnngarment.body.anny_model import AnnyBodyModel

        return AnnyBodyModel(rest_pose=config.anny_rest_pose)
    if config.model == "smpl":
        from gnngarment.body.smpl_model import SMPLBodyModel

        return SMPLBodyModel(config.smpl_model_path, gender=config.smpl_gender)
    raise ValueError(f"unknown body model '{config.model}' (expected 'anny' or 'smpl')")
