"""The bodies of a synthetic build: the Anny body model, made once per process (a
worker keeps it across its tasks, with either executor), the Anny shape a body plan
stands for, and each body's prepared-cache file (``bodies/<name>.npz``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from data_prep.config import DataConfig
from data_prep.plan import BodyPlan

#: This process's state, kept across the tasks a worker runs.
_WORKER: dict[str, Any] = {}


def anny_body_model():
    """This process's :class:`~gnngarment.body.anny_model.AnnyBodyModel` (made on the
    first call, about a second with its cache in place)."""
    if "body" not in _WORKER:
        from gnngarment.body.anny_model import AnnyBodyModel

        _WORKER["body"] = AnnyBodyModel()
    return _WORKER["body"]


def anny_shape(plan: BodyPlan):
    """The :class:`~gnngarment.body.anny_model.AnnyShape` of a body plan."""
    from gnngarment.body.anny_model import AnnyShape

    return AnnyShape(**plan.shape)


def prepare_body(root: Path, plan: BodyPlan, config: DataConfig) -> None:
    """Write ``bodies/<name>.npz`` (rest joints, D, subset)."""
    from gnngarment.data.body_inputs import body_shape_inputs
    from gnngarment.data.cache import BodyRecord, write_body

    inputs = body_shape_inputs(anny_body_model(), anny_shape(plan), config.body_vertices)
    write_body(root, BodyRecord(name=plan.name, joints=inputs.joints,
                                distances=inputs.distances, subset=inputs.subset))
