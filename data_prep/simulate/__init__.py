"""Reference cloth simulation (NVIDIA Newton, VBD solver on the CPU) of the synthetic set.

A pure function of arrays — :func:`simulate_garment` — plus its settings, fabric presets,
result and failure types. Importing this package is cheap: Warp and Newton are imported
(and their kernels compiled, ~25–45 s on an empty Warp cache) only when a simulation runs.
"""

from data_prep.simulate.drape import DrapeResult, drape_garment
from data_prep.simulate.fabrics import FABRICS, FabricPreset, resolve_fabric
from data_prep.simulate.quality import QualityReport
from data_prep.simulate.settings import SimulationSettings, load_simulation_settings
from data_prep.simulate.simulate import SimulationFailed, SimulationResult, simulate_garment

__all__ = [
    "FABRICS",
    "DrapeResult",
    "FabricPreset",
    "QualityReport",
    "SimulationFailed",
    "SimulationResult",
    "SimulationSettings",
    "drape_garment",
    "load_simulation_settings",
    "resolve_fabric",
    "simulate_garment",
]
