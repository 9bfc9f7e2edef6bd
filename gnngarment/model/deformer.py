"""The full garment deformer of the blueprint (Fig. 2): encoders, fusion, skinning
weights, multilevel blend shapes and linear blend skinning.

The work is split as the blueprint prescribes: :meth:`GarmentDeformer.encode` runs
the per garment–body pair part once (E^gg, E^gs, E^bs → ``X^fuse``);
:meth:`GarmentDeformer.forward` runs the per-frame part (E^t1, E^t2, M^mp, LBS) for any
number of frames against that context.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import torch
from torch import nn

from gnngarment.body.skeleton import NUM_JOINTS
from gnngarment.body.skinning import skin
from gnngarment.data.pair import GarmentBodyPair
from gnngarment.data.vertex_features import VERTEX_FEATURE_CHANNELS
from gnngarment.geometry.hierarchy import PoolHierarchy
from gnngarment.model.body_shape_encoder import BodyShapeEncoder
from gnngarment.model.config import ModelConfig
from gnngarment.model.garment_encoder import GarmentGraphEncoder
from gnngarment.model.graph_levels import GraphLevels, repeated_level_graph, stack_hierarchies
from gnngarment.model.motion_encoder import MotionEncoder
from gnngarment.model.multilevel_processor import MultilevelProcessor
from gnngarment.model.oscillator import (
    OscillatorHead,
    OscillatorParameters,
    OscillatorState,
    oscillator_drive,
    oscillator_response,
)
from gnngarment.model.skinning_weight_head import SkinningWeightHead, body_prior_logits
from gnngarment.model.style_encoder import StyleEncoder

#: Scale of the supervised submodule's initial output weights (see ``__init__``).
OUTPUT_INIT_SCALE = 0.01

#: Per-frame motion state: 24 axis-angles + root displacement (blueprint Eq. 6).
MOTION_CHANNELS = 3 * (NUM_JOINTS + 1)


@dataclass
class DeformerContext:
    """Per-pair results of :meth:`GarmentDeformer.encode`, reused for every frame.

    Attributes:
        fused: ``(ΣN, S, F)`` ``X^fuse`` of all pairs, concatenated along vertices.
        rest_pos: ``(ΣN, 3)``.
        ptr: ``(P + 1,)`` vertex offsets of the pairs.
        hierarchies: one per pair.
        prior_logits: ``(ΣN, 24)`` the weight head's body-skinning prior
            (:func:`body_prior_logits`, ``-inf`` on joints out of ``weight_reach``), or
            ``None`` when the model has no prior.
        active_channels: ``(k,)`` long, the columns of ``fused.flatten(1)`` that are
            non-zero at some vertex, or ``None`` when all are. ``X^fuse`` is a product
            of ReLU outputs and most of its columns are zero at every vertex (257 of
            384 for the shipped model on the benchmark skirt): M^mp's input
            ``flatten(X^fuse) ⊙ E^t2`` is zero there for every frame, so the embedding
            GATs read only these columns — the same output, and no gradient is lost
            (a ReLU passes none back through a zero).
        motion_mask: ``(P, 75)`` and velocity_mask ``(P, 3 N_b')``, 1 where a pair's
            motion encoders see the input and 0 where ``motion_reach`` hides it
            (:func:`motion_input_masks`), or ``None`` when they see everything.
        body_weights: ``(ΣN, 24)`` the pairs' transferred body skinning weights (the
            oscillators' drive frame), or ``None`` when the pairs have none.
    """

    fused: torch.Tensor
    rest_pos: torch.Tensor
    ptr: list[int]
    hierarchies: list[PoolHierarchy]
    prior_logits: torch.Tensor | None = None
    active_channels: torch.Tensor | None = None
    motion_mask: torch.Tensor | None = None
    velocity_mask: torch.Tensor | None = None
    body_weights: torch.Tensor | None = None
    _graphs: dict[int, GraphLevels] = field(default_factory=dict, repr=False)

    @property
    def num_pairs(self) -> int:
        return len(self.hierarchies)


@dataclass
class DeformerOutput:
    """Per-frame outputs for ``P`` pairs × ``B`` frames, concatenated item by item
    (item ``k = p·B + b`` holds pair ``p``'s ``N_p`` vertices at frame ``b``).

    Attributes:
        weights: ``(V, 24)`` skinning weights ``W^t`` (rows sum to 1).
        blend_shapes: ``(V, 3)`` ``B^t`` (metres, rest frame).
        supervised_blend_shapes: ``(V, 3)`` the supervised submodule's part of ``B^t``.
        dynamic_blend_shapes: ``(V, 3)`` the oscillators' part of ``B^t`` (the offsets
            passed to :meth:`GarmentDeformer.forward`), or ``None`` without dynamics.
        posed: ``(V, 3)`` ``M^t`` (metres, world).
        item: ``(V,)`` item index of every vertex.
        item_ptr: ``(P·B + 1,)`` vertex offsets of the items.
    """

    weights: torch.Tensor
    blend_shapes: torch.Tensor
    supervised_blend_shapes: torch.Tensor
    posed: torch.Tensor
    item: torch.Tensor
    item_ptr: torch.Tensor
    dynamic_blend_shapes: torch.Tensor | None = None

    @property
    def static_blend_shapes(self) -> torch.Tensor:
        """``(V, 3)`` the blend shapes of the submodules alone (without the oscillators)."""
        if self.dynamic_blend_shapes is None:
            return self.blend_shapes
        return self.blend_shapes - self.dynamic_blend_shapes

    def split(self, name: str, pair_sizes: Sequence[int], frames: int) -> list[torch.Tensor]:
        """One ``(B, N_p, C)`` tensor per pair for the output field ``name``."""
        tensor = getattr(self, name)
        pieces, start = [], 0
        for size in pair_sizes:
            pieces.append(tensor[start:start + size * frames].view(frames, size, -1))
            start += size * frames
        return pieces


class GarmentDeformer(nn.Module):
    """Skinning weights and blend shapes for any garment on any body and motion.

    Args:
        config: widths and variants (:class:`ModelConfig`).
    """

    def __init__(self, config: ModelConfig):
        super().__init__()
        config.validate()
        self.config = config
        width = config.feature_channels
        self.garment_encoder = GarmentGraphEncoder(VERTEX_FEATURE_CHANNELS,
                                                   list(config.garment_channels), NUM_JOINTS,
                                                   config.dropout, attention=config.attention)
        self.style_encoder = StyleEncoder(config.landmarks, list(config.style_channels))
        self.body_encoder = BodyShapeEncoder(config.body_vertices, list(config.body_channels))
        self.pose_encoder = MotionEncoder(MOTION_CHANNELS, config.motion_hidden,
                                          config.motion_layers)
        self.velocity_encoder = MotionEncoder(3 * config.body_vertices, width * NUM_JOINTS,
                                              config.motion_layers)
        self.weight_head = SkinningWeightHead(body_prior=config.weight_prior == "body")

        def processor() -> MultilevelProcessor:
            return MultilevelProcessor(width * NUM_JOINTS, config.processor_channels,
                                       config.processor_heads, 3, config.output_heads,
                                       config.levels, config.pooling, config.pooling_ratio,
                                       config.dropout, attention=config.attention)

        self.supervised_processor = processor()
        # Blend shapes are corrections of centimetres: a Glorot-initialised output GAT
        # predicts ~1 m offsets from the tanh features, which the first epochs would spend
        # undoing. Scaled down, the untrained model starts near plain skinning while every
        # layer still receives gradients.
        with torch.no_grad():
            self.supervised_processor.output.lin.weight.mul_(OUTPUT_INIT_SCALE)
        self.physics_processor = processor() if config.physics_submodule else None
        if self.physics_processor is not None:
            # The physics stage starts from the supervised solution: its submodule adds
            # exactly zero until trained (output weights zero, inner layers as usual).
            nn.init.zeros_(self.physics_processor.output.lin.weight)
            nn.init.zeros_(self.physics_processor.output.bias)
        #: Per-vertex oscillator modes from X^fuse (zero gain until trained: a model
        #: warm-started from one without dynamics starts with the same output).
        self.oscillator_head = (OscillatorHead(width * NUM_JOINTS, config.dynamics_modes)
                                if config.dynamics_modes else None)
        #: Whether forward adds the physics submodule (off during the supervised stage).
        self.use_physics = False

    # ---------------------------------------------------------------- per pair
    def encode(self, pairs: Sequence[GarmentBodyPair]) -> DeformerContext:
        """Encode garments and bodies once: ``X^fuse = X̂^gg ⊙ C^bs`` (Eq. 5).

        Shapes: see :class:`GarmentBodyPair`; returns ``fused (ΣN, 24, F)``.
        """
        if not pairs:
            raise ValueError("encode() needs at least one garment-body pair")
        sizes = [int(pair.rest_pos.shape[0]) for pair in pairs]
        for index, pair in enumerate(pairs):
            try:
                check_pair_fits(pair, self.config)
            except ValueError as error:
                raise ValueError(f"pair {index}: {error}") from None
        device = pairs[0].features.device
        features = torch.cat([pair.features for pair in pairs])
        edge_index = torch.cat([
            torch.as_tensor(pair.hierarchy.edge_index, device=device) + offset
            for pair, offset in zip(pairs, _offsets(sizes), strict=False)], dim=1)
        pair_of_vertex = torch.repeat_interleave(torch.arange(len(pairs), device=device),
                                                 torch.tensor(sizes, device=device))
        style = self.style_encoder(torch.stack([pair.descriptor for pair in pairs]))
        # The garments' own structures, kept between calls (a training run sees the same
        # garments batch after batch; see graph_levels.level_graph).
        structure = (repeated_level_graph([(pair.hierarchy, 1) for pair in pairs], 0, device)
                     if self.config.attention == "csr" else None)
        garment = self.garment_encoder(features, edge_index, style[pair_of_vertex], structure)
        body = self.body_encoder(torch.stack([pair.body_distances for pair in pairs]))
        fused = garment * body[pair_of_vertex]
        # Checked above: every pair has body weights when the head has the prior.
        pair_logits = ([body_prior_logits(p.body_weights, p.rest_pos, p.joint_distances,
                                          self.config.weight_reach) for p in pairs]
                       if self.weight_head.body_prior else None)
        prior_logits = None if pair_logits is None else torch.cat(pair_logits)
        motion_mask = velocity_mask = None
        if (self.config.motion_reach and self.config.weight_reach is not None
                and pair_logits is not None):
            masks = [motion_input_masks(logits, pair.body_distances)
                     for logits, pair in zip(pair_logits, pairs, strict=True)]
            motion_mask = torch.stack([m for m, _ in masks])
            velocity_mask = torch.stack([v for _, v in masks])
        return DeformerContext(fused=fused, rest_pos=torch.cat([p.rest_pos for p in pairs]),
                               ptr=_offsets(sizes), hierarchies=[p.hierarchy for p in pairs],
                               prior_logits=prior_logits, active_channels=_active_channels(fused),
                               motion_mask=motion_mask, velocity_mask=velocity_mask,
                               body_weights=(torch.cat([p.body_weights for p in pairs])
                                             if all(p.body_weights is not None for p in pairs)
                                             else None))

    # ---------------------------------------------------------------- dynamics
    @property
    def has_dynamics(self) -> bool:
        return self.oscillator_head is not None

    def oscillator_parameters(self, context: DeformerContext) -> list[OscillatorParameters]:
        """Every pair's modes (frequency, damping, gain per vertex) from its ``X^fuse``."""
        if self.oscillator_head is None:
            raise ValueError("this model has no dynamics (dynamics_modes is 0)")
        return [self.oscillator_head(context.fused[context.ptr[p]:context.ptr[p + 1]]
                                     .flatten(1)) for p in range(context.num_pairs)]

    def dynamic_blend_shapes(self, context: DeformerContext,
                             joint_transforms: Sequence[torch.Tensor],
                             frames: torch.Tensor, fps: float) -> torch.Tensor:
        """The oscillators' blend shapes at chosen frames of whole sequences, in the
        item order of :meth:`forward` (training: any frames of a sequence in one pass,
        by the response's convolution over the sequence's history from frame 0).

        Shapes: joint_transforms ``P`` tensors ``(T_p, 24, 4, 4)`` (each pair's whole
        sequence), frames ``(P, B)`` long → ``(B · ΣN, 3)`` metres, rest frame.
        """
        parameters = self.oscillator_parameters(context)
        pieces = []
        for p, (modes, transforms) in enumerate(zip(parameters, joint_transforms,
                                                    strict=True)):
            rest = context.rest_pos[context.ptr[p]:context.ptr[p + 1]]
            drive = oscillator_drive(rest, context.body_weights[context.ptr[p]:
                                                                context.ptr[p + 1]],
                                     transforms, fps)
            pieces.append(oscillator_response(drive, modes, fps)[frames[p]].flatten(0, 1))
        return pieces[0] if len(pieces) == 1 else torch.cat(pieces)

    def dynamics_stream(self, context: DeformerContext, fps: float) -> DynamicsStream:
        """A frame-by-frame carrier of the oscillators' state for the single pair of
        ``context`` (inference in chunks)."""
        if context.num_pairs != 1:
            raise ValueError(f"a dynamics stream follows one pair, got {context.num_pairs}")
        return DynamicsStream(self.oscillator_parameters(context)[0], context.rest_pos,
                              context.body_weights, fps)

    # ---------------------------------------------------------------- per frame
    def forward(self, context: DeformerContext, motion_windows: torch.Tensor,
                velocity_windows: torch.Tensor, joint_transforms: torch.Tensor,
                dynamic_offsets: torch.Tensor | None = None) -> DeformerOutput:
        """Deform every pair of ``context`` for ``B`` frames each.

        Shapes:
            motion_windows: ``(P, B, m, 75)`` joint axis-angles + root displacement.
            velocity_windows: ``(P, B, m, 3 N_b')`` body-subset velocities (m/s).
            joint_transforms: ``(P, B, 24, 4, 4)`` skinning transforms of the frames.
            dynamic_offsets: ``(B · ΣN, 3)`` the oscillators' blend shapes of these
                frames (:meth:`dynamic_blend_shapes`, :meth:`dynamics_stream`), added to
                the submodules'; required when the model has dynamics.

        Returns:
            :class:`DeformerOutput` with ``V = B · ΣN`` rows.
        """
        if self.has_dynamics and dynamic_offsets is None:
            raise ValueError("this model has dynamics: pass dynamic_offsets (the "
                             "oscillators' blend shapes of the frames)")
        pairs, frames = context.num_pairs, motion_windows.shape[1]
        _check_frames(motion_windows, velocity_windows, joint_transforms, pairs, self.config)
        width = self.config.feature_channels
        if context.motion_mask is not None and context.velocity_mask is not None:
            motion_windows = motion_windows * context.motion_mask[:, None, None, :]
            velocity_windows = velocity_windows * context.velocity_mask[:, None, None, :]
        pose_code, _ = self.pose_encoder(motion_windows.flatten(0, 1))       # (P·B, F)
        velocity_code, _ = self.velocity_encoder(velocity_windows.flatten(0, 1))  # (P·B, S·F)
        pose_code = pose_code.view(pairs, frames, width)
        velocity_code = velocity_code.view(pairs, frames, NUM_JOINTS * width)

        active = context.active_channels
        if active is not None:
            velocity_code = velocity_code.index_select(2, active)
        weights, processor_input = [], []
        for p in range(pairs):
            fused = context.fused[context.ptr[p]:context.ptr[p + 1]]           # (N, S, F)
            prior = (None if context.prior_logits is None else
                     context.prior_logits[context.ptr[p]:context.ptr[p + 1]])
            weights.append(self.weight_head(fused, pose_code[p], prior).flatten(0, 1))  # Eq. 6
            flat = fused.flatten(1) if active is None else fused.flatten(1).index_select(1, active)
            processor_input.append((flat[None] * velocity_code[p][:, None, :]).flatten(0, 1))
        # One pair (inference): its tensors as they are (cat would copy the (B·N, k) input).
        weights_all = weights[0] if pairs == 1 else torch.cat(weights)
        x = processor_input[0] if pairs == 1 else torch.cat(processor_input)   # Eq. 7

        graph = self._graph_levels(context, frames, x.device)
        supervised = self.supervised_processor(x, graph, active)               # Eq. 8
        blend = supervised
        if self.use_physics and self.physics_processor is not None:
            blend = supervised + self.physics_processor(x, graph, active)
        if dynamic_offsets is not None:
            if tuple(dynamic_offsets.shape) != tuple(blend.shape):
                raise ValueError(f"dynamic_offsets must be {tuple(blend.shape)} (B · ΣN, 3), "
                                 f"got {tuple(dynamic_offsets.shape)}")
            blend = blend + dynamic_offsets.to(blend.dtype)

        sizes = [context.ptr[p + 1] - context.ptr[p] for p in range(pairs)]
        rest = torch.cat([context.rest_pos[context.ptr[p]:context.ptr[p + 1]].repeat(frames, 1)
                          for p in range(pairs)])
        item_sizes = torch.tensor([s for s in sizes for _ in range(frames)], device=x.device)
        item = torch.repeat_interleave(torch.arange(pairs * frames, device=x.device), item_sizes)
        posed = skin(rest, blend, weights_all, joint_transforms.flatten(0, 1), batch=item)
        item_ptr = torch.cat([item_sizes.new_zeros(1), torch.cumsum(item_sizes, 0)])
        return DeformerOutput(weights=weights_all, blend_shapes=blend,
                              supervised_blend_shapes=supervised, posed=posed, item=item,
                              item_ptr=item_ptr, dynamic_blend_shapes=dynamic_offsets)

    def _graph_levels(self, context: DeformerContext, frames: int,
                      device: torch.device) -> GraphLevels:
        # Index structures depend only on topology and B: build once per context and B.
        if frames not in context._graphs:
            hierarchies = [h for h in context.hierarchies for _ in range(frames)]
            levels = self.config.levels if self.config.pooling == "structure" else 0
            graph = stack_hierarchies(hierarchies, levels)
            graph.edge_index = [e.to(device) for e in graph.edge_index]
            graph.batch = [b.to(device) for b in graph.batch]
            graph.kept = [k.to(device) for k in graph.kept]
            graph.unpool = [u.to(device) for u in graph.unpool]
            context._graphs[frames] = graph
        return context._graphs[frames]


class DynamicsStream:
    """The oscillators of one garment–body pair run chunk by chunk: the state (and the two
    previous frames the drive's acceleration needs) carried from one chunk to the next,
    so a sequence in chunks gets the blend shapes of one pass (a test: within 1e-5 m).

    Args:
        parameters: the pair's modes; rest_pos ``(N, 3)``; body_weights ``(N, 24)``;
        fps: frames per second of the motion.
    """

    def __init__(self, parameters: OscillatorParameters, rest_pos: torch.Tensor,
                 body_weights: torch.Tensor | None, fps: float):
        if body_weights is None:
            raise ValueError("dynamics need the pair's body skinning weights")
        self.parameters, self.rest_pos, self.body_weights, self.fps = (
            parameters, rest_pos, body_weights, fps)
        self.state = OscillatorState.start(rest_pos.shape[0], parameters.frequency.shape[1],
                                           rest_pos.device)
        self._history: torch.Tensor | None = None   # (2, 24, 4, 4): the last two frames

    def advance(self, joint_transforms: torch.Tensor) -> torch.Tensor:
        """Blend shapes ``(B, N, 3)`` (metres, rest frame) of the next ``B`` frames, given
        their joint transforms ``(B, 24, 4, 4)``."""
        history = (joint_transforms[:1].expand(2, -1, -1, -1) if self._history is None
                   else self._history)
        extended = torch.cat([history.to(joint_transforms.dtype), joint_transforms])
        # The drive's backward difference sees the two frames before the chunk, as in
        # one pass (whose frames before 0 are frame 0: the same as this first history).
        drive = oscillator_drive(self.rest_pos, self.body_weights, extended, self.fps)[2:]
        offsets, self.state = self.state.advance(drive, self.parameters, self.fps)
        self._history = extended[-2:]
        return offsets


def motion_input_masks(prior_logits: torch.Tensor, body_distances: torch.Tensor
                       ) -> tuple[torch.Tensor, torch.Tensor]:
    """Which motion inputs a garment's encoders see under ``motion_reach``: the rotations
    of the joints the weight reach lets move at least one of its vertices (a finite
    prior logit), the root displacement always, and the velocities of the body-subset
    vertices whose nearest joint is one of those.

    Shapes: prior_logits ``(N, 24)`` (``-inf`` out of reach), body_distances
    ``(N_b', 24)`` metres → ``(75,)`` and ``(3 N_b',)`` float masks (1 seen, 0 hidden).
    """
    joints = torch.isfinite(prior_logits).any(dim=0).to(prior_logits.dtype)     # (24,)
    motion = torch.cat([joints.repeat_interleave(3), joints.new_ones(3)])
    nearest = body_distances.argmin(dim=1)                                        # (N_b',)
    return motion, joints[nearest].repeat_interleave(3)


def _active_channels(fused: torch.Tensor) -> torch.Tensor | None:
    """``(k,)`` the columns of ``fused.flatten(1)`` non-zero at some vertex (NaN counts as
    non-zero), or ``None`` when that is all of them. Shapes: fused ``(ΣN, S, F)``."""
    nonzero = (fused.detach().flatten(1) != 0).any(0)
    if bool(nonzero.all()):
        return None
    return nonzero.nonzero().squeeze(1)


def _offsets(sizes: Sequence[int]) -> list[int]:
    offsets = [0]
    for size in sizes:
        offsets.append(offsets[-1] + size)
    return offsets


def check_pair_fits(pair: GarmentBodyPair, config: ModelConfig) -> None:
    """Raise ``ValueError`` (naming the array, and the setting where one decides its
    shape) when ``pair`` does not fit a model of ``config``: wrong shapes or non-finite
    values, a descriptor of another length than ``landmarks``, body features for
    another ``body_vertices``, fewer pooling levels than the model pools, no body
    weights for the ``body`` prior, or no joint distances for its ``weight_reach``.
    :meth:`GarmentDeformer.encode` checks every pair; a trainer checks its cache's first
    one before any epoch."""
    n = pair.rest_pos.shape[0]
    expected = {
        "rest_pos": (n, 3), "features": (n, VERTEX_FEATURE_CHANNELS),
        "descriptor": (config.landmarks,), "body_distances": (config.body_vertices, NUM_JOINTS),
    }
    setting_of = {"descriptor": "landmarks", "body_distances": "body_vertices"}
    for name, shape in expected.items():
        actual = tuple(getattr(pair, name).shape)
        if actual != shape:
            hint = (f" (the model's {setting_of[name]} is {getattr(config, setting_of[name])})"
                    if name in setting_of else "")
            raise ValueError(f"{name} has shape {actual}, expected {shape}{hint}")
        if not torch.isfinite(getattr(pair, name)).all():
            raise ValueError(f"{name} contains NaN or inf")
    if config.weight_prior == "body":
        _check_per_joint(pair.body_weights, "body_weights", n, "weight_prior 'body' needs "
                         "the garment's transferred body skinning weights")
        if config.weight_reach is not None:
            _check_per_joint(pair.joint_distances, "joint_distances", n, "weight_reach "
                             f"{config.weight_reach} needs how far each joint's body region "
                             "lies from the garment (joint_region_distances)",
                             infinite_allowed=True)   # +inf: a joint that moves no body vertex
    if pair.hierarchy.num_vertices != n:
        raise ValueError(f"hierarchy has {pair.hierarchy.num_vertices} vertices, "
                         f"garment has {n}")
    if config.pooling == "structure" and pair.hierarchy.depth < config.levels:
        raise ValueError(f"its pooling hierarchy has {pair.hierarchy.depth} levels, the "
                         f"model pools {config.levels} (levels)")


def _check_per_joint(values: torch.Tensor | None, name: str, n: int, needed_for: str,
                     infinite_allowed: bool = False) -> None:
    if values is None:
        raise ValueError(f"{name} is missing; {needed_for} ({n}, {NUM_JOINTS})")
    if tuple(values.shape) != (n, NUM_JOINTS):
        raise ValueError(f"{name} has shape {tuple(values.shape)}, expected {(n, NUM_JOINTS)}")
    if (torch.isnan(values) if infinite_allowed else ~torch.isfinite(values)).any():
        raise ValueError(f"{name} contains NaN" + ("" if infinite_allowed else " or inf"))


def _check_frames(motion: torch.Tensor, velocity: torch.Tensor, transforms: torch.Tensor,
                  pairs: int, config: ModelConfig) -> None:
    if motion.dim() != 4 or motion.shape[0] != pairs or motion.shape[-1] != MOTION_CHANNELS:
        raise ValueError(f"motion_windows must be (P={pairs}, B, m, {MOTION_CHANNELS}), "
                         f"got {tuple(motion.shape)}")
    frames, window = motion.shape[1], motion.shape[2]
    if tuple(velocity.shape) != (pairs, frames, window, 3 * config.body_vertices):
        raise ValueError(f"velocity_windows must be ({pairs}, {frames}, {window}, "
                         f"{3 * config.body_vertices}), got {tuple(velocity.shape)}")
    if tuple(transforms.shape) != (pairs, frames, NUM_JOINTS, 4, 4):
        raise ValueError(f"joint_transforms must be ({pairs}, {frames}, {NUM_JOINTS}, 4, 4), "
                         f"got {tuple(transforms.shape)}")
