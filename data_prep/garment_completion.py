"""Garments draped by an older builder gain the arrays a newer one writes, without being
draped again: today the joint distances of cache format 3 (the weight reach measured on
the body, :func:`~gnngarment.body.joint_reach.joint_region_distances`), measured on the
same rest body the drape was made on. A resumed build (``gnngarment prepare`` on an
existing output) completes every garment it keeps, so a format-2 cache becomes a
format-3 one without simulating anything."""

from __future__ import annotations

from pathlib import Path

from data_prep.bodies import anny_body_model, anny_shape
from data_prep.plan import BodyPlan


def complete_garment(root: Path, name: str, body: BodyPlan) -> bool:
    """Add what ``garments/<name>.npz`` lacks (atomically; its inputs hash is unchanged:
    the drape is the same). Returns whether the file was rewritten."""
    from gnngarment.body.joint_reach import joint_region_distances
    from gnngarment.data.cache import read_garment, write_garment

    record = read_garment(root, name)
    if record.joint_distances is not None:
        return False
    model = anny_body_model()
    rest = model.rest(anny_shape(body))
    record.joint_distances = joint_region_distances(
        record.rest_pos, rest.vertices.numpy(), model.skinning_weights())
    write_garment(root, record)
    return True
