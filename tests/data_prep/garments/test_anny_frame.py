"""`anny_body_frame`: Anny's T- and A-pose rest meshes as bodies (two shapes)."""

from __future__ import annotations

import pytest

from data_prep.garments import BodyFrame

pytest.importorskip("anny")


def test_anny_frames(anny_bodies: dict[str, BodyFrame]) -> None:
    import trimesh

    for name, body in anny_bodies.items():
        mesh = trimesh.Trimesh(body.vertices, body.faces, process=False)
        assert mesh.is_watertight and mesh.volume > 0, name
        assert abs(body.joint("pelvis")[2]) < 0.1 and body.vertices[:, 2].max() > 0.6
    t_pose, a_pose = anny_bodies["T"], anny_bodies["A"]
    for body, straight in ((t_pose, True), (a_pose, False)):
        drop = body.joint("L_shoulder")[2] - body.joint("L_wrist")[2]
        assert (abs(drop) < 0.03) == straight
    assert t_pose.joint("L_wrist")[0] > 0.6 and a_pose.joint("L_wrist")[0] < 0.5
