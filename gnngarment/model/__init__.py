"""The network: encoders, multilevel GAT U-Net and the full garment deformer."""

from gnngarment.model.config import POOLING_METHODS, ModelConfig
from gnngarment.model.deformer import DeformerContext, DeformerOutput, GarmentDeformer
from gnngarment.model.graph_levels import GraphLevels, stack_hierarchies
from gnngarment.model.multilevel_processor import MultilevelProcessor

__all__ = [
    "POOLING_METHODS", "DeformerContext", "DeformerOutput", "GarmentDeformer", "GraphLevels",
    "ModelConfig", "MultilevelProcessor", "stack_hierarchies",
]
