"""`BodyFrame`: its joints are looked up in the SMPL-order joint table."""

from __future__ import annotations

from gnngarment.body.skeleton import JOINT_INDEX


def test_joint_table_is_smpl_order() -> None:
    assert JOINT_INDEX["pelvis"] == 0 and JOINT_INDEX["neck"] == 12 and JOINT_INDEX["R_hand"] == 23
