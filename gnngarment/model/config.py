"""Settings of the garment deformer (defaults mirror ``configs/model/paper.yaml``)."""

from __future__ import annotations

from dataclasses import dataclass, field

#: Pooling methods of the multilevel processor: the blueprint's structure-preserving
#: pooling, or PyG's learned poolers (the paper's baselines).
POOLING_METHODS = ("structure", "topk", "sag", "asap")

#: Implementations of the GAT layers: ``csr`` (:class:`~gnngarment.model.graph_attention.
#: GraphAttention`, edge softmax + one CSR matmul) or ``pyg`` (PyG's ``GATConv``, the
#: reference). Both compute the same function with the same parameters.
ATTENTION_IMPLEMENTATIONS = ("csr", "pyg")

#: Priors of the skinning-weight head (Eq. 6): ``body`` starts from the garment's
#: transferred body skinning weights and learns a gated correction; ``none`` is the
#: paper's head, a plain softmax of the learned logits.
WEIGHT_PRIORS = ("body", "none")

#: Most oscillator modes per vertex (``dynamics_modes``).
MAX_DYNAMICS_MODES = 8

#: Most channels of any layer, and most body vertices / landmarks / history frames: a
#: config (a YAML file or a checkpoint's) asking for more is refused before a tensor is
#: allocated (the paper's network has at most 512 channels; 200,000 would take all of
#: this machine's memory).
MAX_CHANNELS = 4096
MAX_HEADS = 64
#: Most per-joint feature channels ``F`` (the paper's 128, twice over): E^t2's LSTM is
#: ``24 F`` wide, its weights grow as ``F²``.
MAX_FEATURE_CHANNELS = 256
MAX_WINDOW = 120

#: Most pooling levels of the multilevel processor (and of a garment's hierarchy that a
#: model can use); a small garment stops shrinking well before this.
MAX_LEVELS = 6


@dataclass
class ModelConfig:
    """Widths and variants of :class:`~gnngarment.model.deformer.GarmentDeformer`.

    Attributes:
        garment_channels: per-head output channels of every E^gg GAT block; the style
            cues multiply the features before the last block. The last entry is ``F``.
        style_channels: E^gs MLP widths (last = ``F``).
        body_channels: E^bs MLP widths (last = ``F``).
        motion_hidden: E^t1 LSTM hidden size (= ``F``).
        motion_layers: layers of both LSTMs.
        processor_channels: channels of every M^mp GAT but the output one.
        processor_heads: heads of the M^mp GATs (averaged).
        output_heads: heads of the output GAT (3 channels, averaged).
        levels: pooling levels of M^mp (0 = single level; 2 is the blueprint's best).
        pooling: one of :data:`POOLING_METHODS`.
        pooling_ratio: kept fraction for the learned PyG poolers.
        physics_submodule: include the second M^mp trained by the physics stage.
        landmarks: ``N*``, length of the Nyström descriptor (E^gs input).
        body_vertices: ``N_b'``, size of the body-vertex subset (E^bs input, E^t2 input/3).
        window: ``m``, frames of motion history seen by the LSTMs.
        dropout: attention dropout of the GATs (0 = none).
        attention: one of :data:`ATTENTION_IMPLEMENTATIONS`; checkpoints load into either.
        weight_prior: one of :data:`WEIGHT_PRIORS`. ``body``: ``W = softmax(log(max(W_body,
            1e-6)) + g · logits)`` with the garment's transferred body skinning weights
            ``W_body`` (``GarmentBodyPair.body_weights``) and a learnable gate ``g``
            initialised to 0, so the untrained head is exactly body skinning and training
            learns the correction. ``none``: ``W = softmax(logits)`` (the paper's head;
            what checkpoints saved before this setting existed load as).
        weight_reach: with the ``body`` prior, the distance (metres) beyond which a
            joint may not move a garment vertex: joints whose body region (body vertices
            it moves by at least 0.1) lies farther than that beyond the vertex's nearest
            body point (``GarmentBodyPair.joint_distances``), or whose garment region
            (garment vertices its transferred weight moves by at least 0.1) lies
            farther than that from the vertex, get no weight at all; the far-joint
            metric's bound at the same distance holds by construction.
            ``None`` (what checkpoints saved before it existed load as) allows
            every joint. The paper's head (``weight_prior: none``) has no prior to
            limit and ignores it.
        motion_reach: the motion encoders see only the joints that ``weight_reach``
            lets move some vertex of the garment: the other joints' rotations and the
            velocities of the body-subset vertices nearest to them are zeroed, per
            garment–body pair, so a wrist cannot move a skirt through the blend shapes
            either. Without the ``body`` prior and a ``weight_reach`` there is no reach
            and it is ignored. ``False`` (what checkpoints saved before it existed load
            as) shows every joint.
        dynamics_modes: ``K`` driven, damped oscillator modes per vertex added to the
            blend shapes (:mod:`gnngarment.model.oscillator`): the garment keeps moving
            after the body stops. Their drive is the acceleration of each vertex's
            body-skinning frame, so it needs the ``body`` prior's transferred weights.
            0 (what checkpoints saved before it existed load as): none.
    """

    garment_channels: list[int] = field(default_factory=lambda: [32, 64, 128, 128])
    style_channels: list[int] = field(default_factory=lambda: [256, 256, 128])
    body_channels: list[int] = field(default_factory=lambda: [512, 256, 128])
    motion_hidden: int = 128
    motion_layers: int = 2
    processor_channels: int = 32
    processor_heads: int = 4
    output_heads: int = 4
    levels: int = 2
    pooling: str = "structure"
    pooling_ratio: float = 0.5
    physics_submodule: bool = True
    landmarks: int = 64
    body_vertices: int = 512
    window: int = 5
    dropout: float = 0.0
    attention: str = "csr"
    weight_prior: str = "body"
    weight_reach: float | None = 0.2
    motion_reach: bool = True
    dynamics_modes: int = 0

    def __post_init__(self) -> None:
        # Checked on construction, like every other config dataclass: an inconsistent
        # model config cannot exist, whether it came from YAML, a checkpoint or code.
        self.validate()

    @property
    def feature_channels(self) -> int:
        """``F``: per-joint width of the fused garment–body features."""
        return self.garment_channels[-1]

    def validate(self) -> None:
        """Raise ``ValueError`` for inconsistent settings (naming the field)."""
        width = self.feature_channels
        if len(self.garment_channels) < 2 or min(self.garment_channels) < 1:
            raise ValueError("garment_channels needs >= 2 positive widths (the style cues "
                             f"multiply the input of the last block), got {self.garment_channels}")
        if self.garment_channels[-2] != width:
            raise ValueError("garment_channels[-2] must equal F = garment_channels[-1] (the "
                             f"style cues have F channels), got {self.garment_channels}")
        for name in ("style_channels", "body_channels"):
            channels = getattr(self, name)
            if not channels or channels[-1] != width:
                raise ValueError(f"{name} must end with F = garment_channels[-1] = {width}, "
                                 f"got {channels}")
        if self.motion_hidden != width:
            raise ValueError(f"motion_hidden must equal F = {width}, got {self.motion_hidden}")
        if self.pooling not in POOLING_METHODS:
            raise ValueError(f"pooling must be one of {POOLING_METHODS}, got '{self.pooling}'")
        if self.attention not in ATTENTION_IMPLEMENTATIONS:
            raise ValueError(f"attention must be one of {ATTENTION_IMPLEMENTATIONS}, "
                             f"got '{self.attention}'")
        if self.weight_prior not in WEIGHT_PRIORS:
            raise ValueError(f"weight_prior must be one of {WEIGHT_PRIORS}, "
                             f"got '{self.weight_prior}'")
        if self.weight_reach is not None and not self.weight_reach > 0:
            raise ValueError(f"weight_reach must be positive (metres) or null, "
                             f"got {self.weight_reach}")
        if not 0 <= self.levels <= MAX_LEVELS:
            raise ValueError(f"levels must be in 0..{MAX_LEVELS}, got {self.levels}")
        if not 0 < self.pooling_ratio < 1:
            raise ValueError(f"pooling_ratio must be in (0, 1), got {self.pooling_ratio}")
        if not 0 <= self.dynamics_modes <= MAX_DYNAMICS_MODES:
            raise ValueError(f"dynamics_modes must be in 0..{MAX_DYNAMICS_MODES}, "
                             f"got {self.dynamics_modes}")
        if self.dynamics_modes and self.weight_prior != "body":
            raise ValueError("dynamics_modes needs weight_prior 'body' (the oscillators are "
                             "driven by the body-skinning frame of every vertex)")
        for name in ("garment_channels", "style_channels", "body_channels"):
            if max(getattr(self, name)) > MAX_CHANNELS:
                raise ValueError(f"{name} must be at most {MAX_CHANNELS} channels, "
                                 f"got {getattr(self, name)}")
        if width > MAX_FEATURE_CHANNELS:
            raise ValueError(f"garment_channels[-1] (F) must be at most {MAX_FEATURE_CHANNELS} "
                             f"(the velocity LSTM is 24 F wide), got {width}")
        limits = {"motion_hidden": MAX_CHANNELS, "processor_channels": MAX_CHANNELS,
                  "landmarks": MAX_CHANNELS, "body_vertices": MAX_CHANNELS,
                  "processor_heads": MAX_HEADS, "output_heads": MAX_HEADS,
                  "motion_layers": 16, "window": MAX_WINDOW}
        for name, limit in limits.items():
            if getattr(self, name) > limit:
                raise ValueError(f"{name} must be at most {limit}, got {getattr(self, name)}")
        for name in ("motion_layers", "processor_channels", "processor_heads", "output_heads",
                     "landmarks", "body_vertices", "window"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
