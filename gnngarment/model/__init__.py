"""The network: encoders, multilevel GAT U-Net and the full garment deformer."""

from gnngarment.data.pair import GarmentBodyPair
from gnngarment.data.vertex_features import VERTEX_FEATURE_CHANNELS, garment_vertex_features
from gnngarment.model.config import POOLING_METHODS, ModelConfig
from gnngarment.model.deformer import DeformerContext, DeformerOutput, GarmentDeformer
from gnngarment.model.graph_levels import GraphLevels, stack_hierarchies
from gnngarment.model.multilevel_processor import MultilevelProcessor

__all__ = [
    "POOLING_METHODS", "VERTEX_FEATURE_CHANNELS", "DeformerContext", "DeformerOutput",
    "GarmentBodyPair", "GarmentDeformer", "GraphLevels", "ModelConfig", "MultilevelProcessor",
    "garment_vertex_features", "stack_hierarchies",
]
