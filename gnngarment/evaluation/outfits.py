"""Evaluate a model on the layered outfits of a prepared cache (garments worn together,
simulated in one scene by the builder: ``outfits`` in a data config, docs/outfits.md).

Each outfit is animated as ``animate a.obj b.obj`` does
(:func:`~gnngarment.inference.outfit.animate_outfit`: every garment by the model, then
the body's and the layers' resolution) from where the simulation started, and scored
against the simulation per garment; its outer garment is also animated alone (the body
resolution only), for the issue-40 bar "as an outfit within +2 % of alone".
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import torch

from gnngarment.body.skinning import skin
from gnngarment.data.body_inputs import BodyMotionInputs, BodyShapeInputs
from gnngarment.data.cache import check_file_hash, read_garment, read_outfit
from gnngarment.data.dataset import PreparedDataset
from gnngarment.evaluation import metrics
from gnngarment.geometry.body_collisions import CollisionSettings
from gnngarment.geometry.garment_layers import LayerSettings, layer_penetration, outward_faces
from gnngarment.model.deformer import GarmentDeformer

#: The body inputs of a cache sequence, as ``animate`` makes them, or ``None``.
BodyInputs = Callable[[str], "tuple[BodyShapeInputs, BodyMotionInputs] | None"]

#: Reported per outfit, in the order of the table.
OUTFIT_METRICS = ("inner_e_verts_mm", "outer_e_verts_mm", "outer_alone_e_verts_mm",
                  "inner_skinning_mm", "outer_skinning_mm", "through_simulation_pct",
                  "through_raw_pct", "through_resolved_pct", "largest_push_mm")


def outfit_names(dataset: PreparedDataset) -> list[str]:
    """The cache's outfits in ``dataset``'s split (none in a cache built without)."""
    return [name for name, info in dataset.manifest.get("outfits", {}).items()
            if info.get("split") == dataset.split]


def evaluate_outfit(model: GarmentDeformer, dataset: PreparedDataset, name: str,
                    body_inputs: BodyInputs, collisions: CollisionSettings | None = None,
                    layers: LayerSettings | None = None) -> dict[str, float] | None:
    """Metrics of one two-garment outfit (inner, outer): E_verts [mm] of each garment as
    an outfit and of the outer one alone, body skinning of each, the share [%] of the
    outer garment's vertices behind the inner one in the simulation, in the network's
    output and after resolution, and the largest layer push per frame [mm]. ``None``
    when the sequence's body cannot be re-posed."""
    from gnngarment.inference.animate import animate
    from gnngarment.inference.outfit import OutfitGarment, animate_outfit

    layers = layers or LayerSettings()
    check_file_hash(dataset.root, dataset.manifest, f"outfits/{name}.npz")
    record = read_outfit(dataset.root, name)
    if len(record.garments) != 2:
        raise ValueError(f"{dataset.root}/outfits/{name}.npz: {len(record.garments)} "
                         "garments; outfits of two are evaluated")
    found = body_inputs(record.sequence)
    if found is None:
        return None
    body, frames = found
    garments = [read_garment(dataset.root, garment) for garment in record.garments]
    outfit = animate_outfit(
        model, [OutfitGarment(g.name, start, g.faces)
                for g, start in zip(garments, record.start_pos, strict=True)],
        body, frames, layers=list(record.garments), collisions=collisions,
        layer_settings=layers)
    inner, outer = (np.asarray(a.posed) for a in outfit.animations)
    alone = np.asarray(animate(model, record.start_pos[1], garments[1].faces, body, frames,
                               collisions=collisions).posed)
    answer_inner, answer_outer = record.positions
    inner_faces = outward_faces(record.start_pos[0], garments[0].faces, body.rest_vertices,
                                body.faces)

    def error(pred: np.ndarray, answer: np.ndarray) -> float:
        return 1000 * float(metrics.vertex_error(pred, answer).mean())

    def skinned(index: int) -> np.ndarray:
        def tensor(array: np.ndarray) -> torch.Tensor:
            return torch.from_numpy(np.asarray(array, dtype=np.float64))

        return skin(tensor(record.start_pos[index]), None, tensor(garments[index].body_weights),
                    tensor(frames.joint_transforms)).numpy()

    stats = outfit.layer_stats.get(1)
    return {
        "inner_e_verts_mm": error(inner, answer_inner),
        "outer_e_verts_mm": error(outer, answer_outer),
        "outer_alone_e_verts_mm": error(alone, answer_outer),
        "inner_skinning_mm": error(skinned(0), answer_inner),
        "outer_skinning_mm": error(skinned(1), answer_outer),
        "through_simulation_pct": 100 * float(layer_penetration(
            answer_outer, answer_inner, inner_faces, layers).mean()),
        "through_raw_pct": 100 * float(outfit.penetration_raw[1].mean()),
        "through_resolved_pct": 100 * float(outfit.penetration[1].mean()),
        "largest_push_mm": 1000 * float(np.max(stats.max_push)) if stats is not None
        else 0.0,
    }


def evaluate_outfits(model: GarmentDeformer, dataset: PreparedDataset, body_inputs: BodyInputs,
                     collisions: CollisionSettings | None = None,
                     layers: LayerSettings | None = None,
                     progress: Callable[[str], None] | None = None
                     ) -> dict[str, dict[str, float]]:
    """:func:`evaluate_outfit` of every outfit of ``dataset``'s split (those whose body
    cannot be re-posed left out), plus ``"mean"`` over them when there are any."""
    results: dict[str, dict[str, float]] = {}
    for name in outfit_names(dataset):
        values = evaluate_outfit(model, dataset, name, body_inputs, collisions, layers)
        if values is not None:
            results[name] = values
        if progress is not None:
            progress(name)
    if results:
        results["mean"] = {key: float(np.mean([r[key] for r in results.values()]))
                           for key in OUTFIT_METRICS}
    return results
