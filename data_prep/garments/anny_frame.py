"""An Anny body as a :class:`BodyFrame`, straight from the ``anny`` package.

For tests and pictures of the garment generator only. The library's body interface
(``gnngarment.body``, T-pose canonical rest, exact joint mapping) is the source of
bodies for the dataset; this module approximates it with Anny's bone heads so the
garment code does not depend on that package: joints are the heads of the bones
listed in :data:`gnngarment.body.anny_model.ANNY_JOINT_BONES` (averaged for feet and
hands; the library's one table), the mesh is the
largest connected component (the body without tongue and eyes).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from data_prep.garments.body_frame import BodyFrame, largest_component
from gnngarment.body.skeleton import JOINT_NAMES


def _rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(3, 3)`` shortest-arc rotation taking direction ``a`` onto ``b``."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v, c = np.cross(a, b), float(a @ b)
    if np.linalg.norm(v) < 1e-12:
        return np.eye(3)
    skew = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + skew + skew @ skew / (1 + c)


def anny_body_frame(model: Any = None, pose: str = "A",
                    phenotype: dict[str, float] | None = None) -> BodyFrame:
    """Anny's rest body and approximate SMPL joints.

    Args:
        model: an ``anny.Anny()`` instance (built if ``None``: ~1 min the first time on
            a machine, then ~1 s).
        pose: ``"A"`` (Anny's native rest pose, arms ~45° down) or ``"T"`` (upper arms,
            forearms and hands turned to point along ±X, close to the library's
            canonical T-pose).
        phenotype: Anny phenotype values in [0, 1] (gender, age, muscle, weight,
            height, proportions); missing ones take Anny's defaults.

    Returns:
        A :class:`BodyFrame`: vertices ``(N_b, 3)``, faces ``(F_b, 3)``, joints ``(24, 3)``.
    """
    import torch

    from gnngarment.body.anny_model import ANNY_JOINT_BONES

    if pose not in ("A", "T"):
        raise ValueError(f"pose must be 'A' or 'T', got {pose!r}")
    if model is None:
        import anny

        model = anny.Anny()
    labels = list(model.bone_labels)
    index = {label: i for i, label in enumerate(labels)}
    kwargs: dict[str, Any] = {}
    if phenotype:
        kwargs["phenotype_kwargs"] = dict(phenotype)
    with torch.no_grad():
        output = model(**kwargs)
    heads = output["rest_bone_heads"][0].double().numpy()
    vertices = output["rest_vertices"][0].double().numpy()
    if pose == "T":
        # Each bone's rotation acts in its parent's rotated frame (world = parents · own),
        # so a child's own rotation aims its rest direction at the target seen from there.
        parameters = {}
        for side, sign in (("L", 1.0), ("R", -1.0)):
            target = np.array([sign, 0.0, 0.0])
            chain = [f"upperarm01.{side}", f"lowerarm01.{side}", f"wrist.{side}"]
            aims = [heads[index[f"lowerarm01.{side}"]], heads[index[f"wrist.{side}"]],
                    heads[[index[b] for b in ANNY_JOINT_BONES[f"{side}_hand"]]].mean(axis=0)]
            total = np.eye(3)
            for bone, aim in zip(chain, aims, strict=True):
                rotation = _rotation_between(aim - heads[index[bone]], total.T @ target)
                transform = np.eye(4)
                transform[:3, :3] = rotation
                parameters[bone] = torch.tensor(transform[None], dtype=torch.float32)
                total = total @ rotation
        with torch.no_grad():
            output = model(pose_parameters=parameters, **kwargs)
        # Posed outputs put the root at the origin; shift back to the rest frame.
        posed_root = output["bone_poses"][0, index["root"], :3, 3].double().numpy()
        shift = heads[index["root"]] - posed_root
        vertices = output["vertices"][0].double().numpy() + shift
        heads = output["bone_poses"][0, :, :3, 3].double().numpy() + shift
    joints = np.stack([heads[[index[b] for b in ANNY_JOINT_BONES[name]]].mean(axis=0)
                       for name in JOINT_NAMES])
    faces = model.faces.detach().cpu().numpy().astype(np.int64)
    vertices, faces = largest_component(vertices, faces)
    return BodyFrame(vertices=vertices, faces=faces, joints=joints)
