"""Attribution analysis (paper Sec. 4.1, Eq. 9, Fig. 3): which garment vertices'
features drive a predicted deformation, as integrated gradients on the graph features,
heatmaps (PNG, PLY) and the influence-field measure."""

from gnngarment.attribution.attribution import (
    FEATURE_GROUPS,
    HEAT_CHANNELS,
    OUTPUTS,
    REDUCTIONS,
    TARGET_KINDS,
    Attribution,
)
from gnngarment.attribution.colors import SCALES, heat_colors, normalise_heat
from gnngarment.attribution.frame_inputs import FrameInputs
from gnngarment.attribution.influence_field import (
    InfluenceField,
    hop_distances,
    influence_field,
    mass_profile,
)
from gnngarment.attribution.integrated_gradients import FeatureResponse, attribute
from gnngarment.attribution.ply import write_attribution_ply
from gnngarment.attribution.render import render_attribution, render_comparison
from gnngarment.attribution.targets import geodesic_region, largest_output_vertex

__all__ = [
    "FEATURE_GROUPS", "HEAT_CHANNELS", "OUTPUTS", "REDUCTIONS", "SCALES", "TARGET_KINDS",
    "Attribution", "FeatureResponse", "FrameInputs", "InfluenceField", "attribute",
    "geodesic_region", "heat_colors", "hop_distances", "influence_field",
    "largest_output_vertex", "mass_profile", "normalise_heat", "render_attribution",
    "render_comparison", "write_attribution_ply",
]
