"""Evaluate a model (and baselines) on a split of a prepared cache."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from gnngarment.body.skinning import skin
from gnngarment.data.cache import read_body, read_garment
from gnngarment.data.dataset import PreparedDataset, window_indices
from gnngarment.evaluation import metrics
from gnngarment.evaluation.outfits import OUTFIT_METRICS, BodyInputs, evaluate_outfits
from gnngarment.evaluation.perturbation import (
    DEFAULT_IRRELEVANT_JOINT,
    IRRELEVANT_JOINT,
    perturb_joint,
)
from gnngarment.geometry.body_collisions import CollisionSettings, resolve_collisions
from gnngarment.model.deformer import GarmentDeformer

#: Reported columns, in the order of the tables. Every metric is of what users get, the
#: garment after collision resolution; ``raw_*`` are of the network's (or baseline's)
#: own output before it.
METRICS = ("e_verts_mm", "raw_e_verts_mm", "e_norm_deg", "collision_pct", "raw_collision_pct",
           "hausdorff_mm", "sted", "spurious_mm", "far_weight_pct")
#: Metrics aggregated by their maximum over sequences, not their frame-weighted mean.
MAXIMUM_METRICS = ("far_weight_pct",)

#: The posed body mesh of a sequence: ``(T, N_b, 3)`` vertices and ``(F_b, 3)`` faces,
#: or ``None`` where it is not known.
BodyMeshes = Callable[[str], "tuple[np.ndarray, np.ndarray] | None"]


@dataclass
class EvaluationReport:
    """Metrics per method and garment type (and ``"all"``), averaged over frames of
    every sequence of the split.

    Attributes:
        results: ``{method: {garment_type: {metric: value}}}``.
        sequences: ``{method: {sequence: {metric: value}}}``.
        split: evaluated split; frames: frames evaluated.
        unresolved: sequences evaluated without collision resolution (no posed body
            mesh known for them): there the metrics equal the ``raw_*`` ones.
        outfits: ``{method: {outfit: {metric: value}}}`` of the split's layered outfits
            (:mod:`gnngarment.evaluation.outfits`; ``"mean"`` over them), empty for a
            cache without.
    """

    split: str
    results: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)
    sequences: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)
    frames: int = 0
    unresolved: list[str] = field(default_factory=list)
    outfits: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)

    def to_json(self) -> str:
        return json.dumps({"split": self.split, "frames": self.frames, "results": self.results,
                           "sequences": self.sequences, "unresolved": self.unresolved,
                           "outfits": self.outfits},
                          indent=2)

    def to_markdown(self) -> str:
        """Table in the layout of the blueprint's Table 1: one row per method, one group
        of columns per garment type."""
        groups = {t for per_type in self.results.values() for t in per_type} - {"all"}
        sources = sorted(groups & {CLIP_MOTIONS, PROCEDURAL_MOTIONS})
        types = sorted(groups - set(sources)) + sources + ["all"]
        header = ["method"] + [f"{t} {m}" for t in types for m in ("E_verts mm", "E_norm °")]
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        for method, per_type in self.results.items():
            cells = [method]
            for t in types:
                values = per_type.get(t)
                cells += (["–", "–"] if values is None else
                          [f"{values['e_verts_mm']:.1f}", f"{values['e_norm_deg']:.1f}"])
            lines.append("| " + " | ".join(cells) + " |")
        lines += ["", "| method | " + " | ".join(METRICS) + " |", "|" + "---|" * (len(METRICS) + 1)]
        for method, per_type in self.results.items():
            values = per_type["all"]
            lines.append(f"| {method} | " + " | ".join(
                "–" if np.isnan(values.get(m, np.nan)) else f"{values[m]:.4g}" for m in METRICS)
                + " |")
        lines += ["", "Metrics are of the garment after collision resolution (what users get); "
                  "raw_* of the network's or baseline's own output."]
        if self.unresolved:
            lines.append(f"Not resolved (no posed body mesh): {len(self.unresolved)} "
                         "sequence(s), whose metrics equal the raw ones.")
        for method, outfits in self.outfits.items():
            lines += ["", f"Layered outfits, {method} (E_verts mm against the simulation of "
                      "both garments in one scene; through: % of the outer garment's "
                      "vertices behind the inner one):", "",
                      "| outfit | inner E_verts | outer E_verts | outer alone | inner body "
                      "skinning | outer body skinning | through: simulation | raw | "
                      "resolved | largest push mm |", "|" + "---|" * 10]
            for name, values in outfits.items():
                cells = [f"{values[m]:.2f}" for m in OUTFIT_METRICS]
                lines.append(f"| {'**mean**' if name == 'mean' else name} | "
                             + " | ".join(cells) + " |")
        return "\n".join(lines)


@torch.inference_mode()
def predict(model: GarmentDeformer, dataset: PreparedDataset, name: str,
            motion_features: np.ndarray | None = None,
            joint_transforms: np.ndarray | None = None, chunk: int = 16,
            return_weights: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """The model's garment for every frame of a sequence, ``(T, N, 3)``; optionally with
    replaced motion features ``(T, 75)`` / joint transforms ``(T, 24, 4, 4)``. With
    ``return_weights``, also its skinning weights ``(T, N, 24)``."""
    model.eval()
    record = dataset.sequence(name)
    garment = dataset.garment_of(name)
    context = model.encode([garment.pair])
    features = torch.from_numpy(record.motion_features if motion_features is None
                                else motion_features)
    transforms = torch.from_numpy(record.joint_transforms if joint_transforms is None
                                  else joint_transforms)
    velocity = torch.from_numpy(record.velocities.reshape(record.num_frames, -1))
    out, weights = [], []
    stream = model.dynamics_stream(context, record.fps) if model.has_dynamics else None
    for start in range(0, record.num_frames, chunk):
        frames = np.arange(start, min(start + chunk, record.num_frames))
        windows = torch.from_numpy(window_indices(frames, model.config.window))
        offsets = None if stream is None else stream.advance(transforms[frames]).flatten(0, 1)
        result = model(context, features[windows][None], velocity[windows][None],
                       transforms[frames][None], offsets)
        out.append(result.posed.view(len(frames), -1, 3))
        if return_weights:
            weights.append(result.weights.view(len(frames), -1, result.weights.shape[-1]))
    if return_weights:
        return torch.cat(out).numpy(), torch.cat(weights).numpy()
    return torch.cat(out).numpy()


def body_skinning_prediction(dataset: PreparedDataset, name: str,
                             joint_transforms: np.ndarray | None = None) -> np.ndarray | None:
    """The body-skinning baseline's garment ``(T, N, 3)``, or ``None`` when the cache
    has no transferred body weights for this garment."""
    info = dataset.manifest["sequences"][name]
    record = read_garment(dataset.root, info["garment"])
    if record.body_weights is None:
        return None
    transforms = (dataset.sequence(name).joint_transforms if joint_transforms is None
                  else joint_transforms)
    posed = skin(torch.from_numpy(record.rest_pos), None,
                 torch.from_numpy(record.body_weights), torch.from_numpy(transforms))
    return posed.numpy()


def sequence_metrics(pred: np.ndarray, dataset: PreparedDataset, name: str,
                     body_mesh: tuple[np.ndarray, np.ndarray] | None = None
                     ) -> dict[str, float]:
    """Frame-averaged metrics of one predicted sequence against its ground truth; the
    collision rate against the posed body mesh ``(vertices (T, N_b, 3), faces)`` when
    given (:func:`metrics.mesh_collision_rate`), else against the cache's body samples."""
    record = dataset.sequence(name)
    garment = dataset.garment_of(name)
    faces = garment.faces.numpy()
    edges = garment.edges.numpy().T
    rest = garment.pair.rest_pos.numpy()
    target = record.positions
    return {
        "e_verts_mm": 1000 * float(metrics.vertex_error(pred, target).mean()),
        "e_norm_deg": float(metrics.normal_error(pred, target, faces).mean()),
        "collision_pct": float(
            metrics.mesh_collision_rate(pred, *body_mesh).mean() if body_mesh is not None
            else metrics.collision_rate(pred, record.body_points, record.body_normals).mean()),
        "hausdorff_mm": 1000 * float(metrics.hausdorff_distance(pred, target).mean()),
        "sted": float(metrics.spatio_temporal_edge_difference(pred, target, edges, rest).mean()),
    }


def resolved_sequence_metrics(pred: np.ndarray, dataset: PreparedDataset, name: str,
                              body_mesh: tuple[np.ndarray, np.ndarray] | None,
                              settings: CollisionSettings | None = None) -> dict[str, float]:
    """:func:`sequence_metrics` of ``pred (T, N, 3)`` after collision resolution against
    the posed body mesh ``(vertices (T, N_b, 3), faces (F_b, 3))``, plus ``raw_e_verts_mm``
    and ``raw_collision_pct`` of ``pred`` itself (measured the same way). With the mesh,
    both collision figures are against it (:func:`metrics.mesh_collision_rate`); without
    one nothing is resolved, the metrics equal the raw ones and collisions are measured
    against the cache's body samples."""
    if body_mesh is not None and len(body_mesh[0]) != len(pred):
        raise ValueError(f"{name}: the posed body has {len(body_mesh[0])} frames, the "
                         f"garment {len(pred)}")
    # With the body mesh at hand, inside means inside the mesh (exact), for the
    # network's output and for what users get alike.
    raw = sequence_metrics(pred, dataset, name, body_mesh)
    values = raw
    if body_mesh is not None:
        vertices, body_faces = body_mesh
        resolved, _ = resolve_collisions(pred, dataset.garment_of(name).faces.numpy(),
                                         vertices, body_faces, settings)
        values = sequence_metrics(resolved, dataset, name, body_mesh)
    return {**values, "raw_e_verts_mm": raw["e_verts_mm"],
            "raw_collision_pct": raw["collision_pct"]}


def spurious_change(model: GarmentDeformer | None, dataset: PreparedDataset, name: str,
                    baseline: np.ndarray, angle: float = 0.6) -> float:
    """Mean garment change (mm) when an irrelevant joint is rotated by ``angle`` rad
    (``model=None``: the body-skinning baseline)."""
    info = dataset.manifest["sequences"][name]
    joint = IRRELEVANT_JOINT.get(dataset.garment_of(name).garment_type, DEFAULT_IRRELEVANT_JOINT)
    record = dataset.sequence(name)
    rest_joints = read_body(dataset.root, info["body"]).joints
    features, transforms = perturb_joint(record.motion_features, record.joint_transforms,
                                         rest_joints, joint, np.array([angle, 0.0, 0.0]))
    if model is None:
        perturbed = body_skinning_prediction(dataset, name, transforms)
    else:
        perturbed = predict(model, dataset, name, features, transforms)
    return 1000 * float(np.linalg.norm(perturbed - baseline, axis=-1).mean())


#: Groups of sequences by where their motion came from, reported beside the garment
#: types when a split holds both (a build with ``motion_files``, docs/data.md).
CLIP_MOTIONS, PROCEDURAL_MOTIONS = "clip motions", "procedural motions"


def motion_sources(dataset: PreparedDataset) -> dict[str, str]:
    """Sequence → :data:`CLIP_MOTIONS` (a motion-capture window: the manifest names its
    file) or :data:`PROCEDURAL_MOTIONS`."""
    return {name: CLIP_MOTIONS if "motion_file" in dataset.manifest["sequences"][name]
            else PROCEDURAL_MOTIONS for name in dataset.sequence_names}


def _aggregate(per_sequence: dict[str, dict[str, float]], types: dict[str, str],
               frames: dict[str, int], sources: dict[str, str] | None = None
               ) -> dict[str, dict[str, float]]:
    grouped: dict[str, list[str]] = {}
    for name in per_sequence:
        grouped.setdefault(types[name], []).append(name)
    if sources and len({sources[n] for n in per_sequence}) > 1:
        for name in per_sequence:
            grouped.setdefault(sources[name], []).append(name)
    grouped["all"] = list(per_sequence)
    result = {}
    for garment_type, names in grouped.items():
        weights = np.array([frames[n] for n in names], dtype=np.float64)
        result[garment_type] = {
            metric: (float(np.max([per_sequence[n].get(metric, np.nan) for n in names]))
                     if metric in MAXIMUM_METRICS else
                     float(np.average([per_sequence[n].get(metric, np.nan) for n in names],
                                      weights=weights)))
            for metric in METRICS}
    return result


def evaluate(models: dict[str, GarmentDeformer], dataset: PreparedDataset,
             body_skinning: bool = True, spurious: bool = True,
             progress: Callable[[str], None] | None = None,
             body_meshes: BodyMeshes | None = None,
             collisions: CollisionSettings | None = None,
             body_skinning_weights: np.ndarray | None = None,
             outfit_body_inputs: BodyInputs | None = None) -> EvaluationReport:
    """Metrics of every model in ``models`` (and the body-skinning baseline) on every
    sequence of ``dataset``'s split, after collision resolution as
    :func:`~gnngarment.inference.animate.animate` does it, with the raw output's
    ``raw_e_verts_mm`` / ``raw_collision_pct`` beside them.

    Args:
        models: method name → model.
        body_skinning: also evaluate the body-skinning baseline (needs transferred
            body weights in the cache).
        spurious: run the spurious-correlation test for the models (on their raw
            output: it measures the network).
        progress: called with a line per evaluated sequence.
        body_meshes: the posed body mesh of a sequence (the cache stores only body
            samples); sequences without one are evaluated unresolved
            (``EvaluationReport.unresolved``).
        collisions: ``ε`` and smoothing; default :class:`CollisionSettings`.
        body_skinning_weights: ``(N_b, 24)`` the body model's skinning weights; with
            ``body_meshes`` it gives ``far_weight_pct``: the largest share (%) of any
            vertex's skinning weight on joints whose body region is more than 20 cm from
            it (:func:`~gnngarment.evaluation.metrics.far_joint_weight`; frame 0 of a
            body mesh is its rest pose).
        outfit_body_inputs: the body inputs of a sequence as ``animate`` makes them; with
            it the split's layered outfits are evaluated too (``report.outfits``).
    """
    report = EvaluationReport(split=dataset.split)
    types = {n: dataset.garment_of(n).garment_type for n in dataset.sequence_names}
    frames = dict(dataset.frame_counts)
    report.frames = int(sum(frames.values()))
    methods: dict[str, dict[str, dict[str, float]]] = {m: {} for m in models}
    if body_skinning:
        methods["body skinning (draped template)"] = {}
    for name in dataset.sequence_names:
        body_mesh = body_meshes(name) if body_meshes is not None else None
        if body_mesh is None:
            report.unresolved.append(name)
        regions = body_mesh is not None and body_skinning_weights is not None
        rest = dataset.garment_of(name).pair.rest_pos.numpy()
        for method, model in models.items():
            pred, weights = predict(model, dataset, name, return_weights=True)
            values = resolved_sequence_metrics(pred, dataset, name, body_mesh, collisions)
            if regions:
                values["far_weight_pct"] = 100 * metrics.far_joint_weight(
                    weights, rest, body_mesh[0][0], body_skinning_weights)["max"]
            if spurious:
                values["spurious_mm"] = spurious_change(model, dataset, name, pred)
            methods[method][name] = values
        if body_skinning:
            pred = body_skinning_prediction(dataset, name)
            if pred is not None:
                values = resolved_sequence_metrics(pred, dataset, name, body_mesh, collisions)
                if regions:
                    garment_weights = dataset.garment_of(name).pair.body_weights.numpy()
                    values["far_weight_pct"] = 100 * metrics.far_joint_weight(
                        garment_weights, rest, body_mesh[0][0], body_skinning_weights)["max"]
                if spurious:
                    values["spurious_mm"] = spurious_change(None, dataset, name, pred)
                methods["body skinning (draped template)"][name] = values
        if progress is not None:
            progress(name)
    if outfit_body_inputs is not None:
        for method, model in models.items():
            outfits = evaluate_outfits(model, dataset, outfit_body_inputs, collisions,
                                       progress=progress)
            if outfits:
                report.outfits[method] = outfits
    for method, per_sequence in methods.items():
        if per_sequence:
            report.sequences[method] = per_sequence
            report.results[method] = _aggregate(per_sequence, types, frames,
                                                motion_sources(dataset))
    return report


def write_report(report: EvaluationReport, markdown: Path | None = None,
                 json_path: Path | None = None) -> None:
    """Write the report's Markdown table and/or JSON atomically."""
    from gnngarment.io.atomic import atomic_write_bytes

    if json_path is not None:
        atomic_write_bytes(json_path, report.to_json().encode())
    if markdown is not None:
        atomic_write_bytes(markdown, (report.to_markdown() + "\n").encode())
