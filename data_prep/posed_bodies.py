"""The posed body meshes of a synthetic cache's sequences, for collision resolution in
``gnngarment evaluate``.

The cache stores per frame only body *samples* (``body_points``); resolving garment
penetrations needs the whole body mesh. A synthetic build is a pure function of its
config (stored in the manifest), so each sequence's body is posed again here exactly as
:func:`data_prep.sequence_worker.simulate_sequence` posed it, and checked against the stored
samples: a cache built by another version of the planner, the motions or the body
model gives no mesh (with a warning) rather than a wrong one.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np

#: Largest difference [m] between a re-posed body vertex coordinate and its stored
#: sample, beyond float16 storage rounding (half a unit in the last place, 2^-11 relative).
MATCH_TOLERANCE = 0.001

BodyMesh = tuple[np.ndarray, np.ndarray]
#: ``(BodyShapeInputs, BodyMotionInputs)`` of one sequence.
BodyInputs = tuple


def synthetic_body_meshes(root: str | Path) -> Callable[[str], BodyMesh | None]:
    """``sequence name → (vertices (T, N_b, 3), faces (F_b, 3))`` of the posed body of a
    synthetic cache (``None`` for a sequence it cannot reproduce, and for every sequence
    of a cache that was not built from a synthetic config, e.g. CLOTH3D's).

    Anny is constructed on the first call (about a second with its cache in place).
    """
    reposed, _ = _reposer(root)

    def body_mesh(name: str) -> BodyMesh | None:
        found = reposed(name)
        return None if found is None else (found[3], found[0].faces)

    return body_mesh


def synthetic_body_inputs(root: str | Path) -> Callable[[str], BodyInputs | None]:
    """``sequence name →`` the model's body inputs for that sequence's body and motion,
    made as ``animate`` makes them (``(BodyShapeInputs, BodyMotionInputs)``,
    :mod:`gnngarment.data.body_inputs`): what animating a cache's outfits needs; ``None``
    as :func:`synthetic_body_meshes`."""
    from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs

    reposed, count = _reposer(root)

    def body_inputs(name: str) -> BodyInputs | None:
        found = reposed(name)
        if found is None:
            return None
        model, shape, motion, _ = found
        return (body_shape_inputs(model, shape, count),
                body_motion_inputs(model, shape, motion, count))

    return body_inputs


def _reposer(root: str | Path) -> tuple[Callable[[str], tuple | None], int]:
    """``sequence name → (body model, shape, motion, posed vertices (T, N_b, 3))`` of a
    synthetic cache's sequence, re-posed from its plan and checked against the stored
    body samples (``None`` where that cannot be done, with a warning where it was
    tried), and the cache's feature-subset size ``N_b'``."""
    from data_prep.config import DataConfig
    from data_prep.plan import plan_dataset, planned_motion
    from gnngarment.config import ConfigError, merge_config
    from gnngarment.data.cache import read_manifest, read_sequence

    root = Path(root)
    manifest = read_manifest(root)

    def nothing(name: str) -> None:
        return None

    if "config" not in manifest:
        return nothing, 0
    try:
        config = merge_config(DataConfig, manifest["config"], source=f"{root}/manifest.json")
        plans = {plan.name: plan for plan in plan_dataset(config)}
    except (ConfigError, ValueError, KeyError) as error:
        warnings.warn(f"{root}: cannot re-plan the build ({error}); collisions are not "
                      "resolved", stacklevel=3)
        return nothing, 0
    state: dict = {}

    def reposed(name: str):
        import torch

        from gnngarment.body.anny_model import AnnyBodyModel, AnnyShape
        plan = plans.get(name)
        if plan is None:
            return None
        if "model" not in state:
            state["model"] = AnnyBodyModel()
        model = state["model"]
        shape = AnnyShape(**plan.body.shape)
        motion = planned_motion(plan.motion, config, model, shape)
        with torch.no_grad():
            vertices = model.pose(motion, shape).vertices.numpy()
        stored = read_sequence(root, name).body_points
        samples = model.feature_vertex_indices(config.collision_points)
        if (stored.shape != (len(vertices), len(samples), 3)
                or (np.abs(vertices[:, samples] - stored)
                    > MATCH_TOLERANCE + np.abs(stored) * 2.0**-11).any()):
            warnings.warn(f"{root}: {name}: the re-posed body does not match the cached "
                          "body samples; its collisions are not resolved", stacklevel=2)
            return None
        return model, shape, motion, vertices

    return reposed, config.body_vertices


def synthetic_skinning_weights(root: str | Path) -> np.ndarray | None:
    """The body model's skinning weights ``(N_b, 24)`` for a synthetic cache (its bodies
    are Anny's: one topology, one set of weights), ``None`` for any other cache."""
    from gnngarment.data.cache import read_manifest

    if "config" not in read_manifest(root):
        return None
    from gnngarment.body.anny_model import AnnyBodyModel

    return AnnyBodyModel().skinning_weights()
