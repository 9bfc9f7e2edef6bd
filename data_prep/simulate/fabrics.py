"""Fabric presets named like CLOTH3D's (cotton, silk, denim, leather), in SI units.

CLOTH3D labels every garment with one of four fabrics. The values below (sources and
reasoning in ``docs/simulation.md``) anchor cotton on the material that SNUG and HOOD use
for learned garment simulation and place the other three relative to it with the ratios
of Blender's cloth presets of the same names, checked against measured fabric ranges.
"""

from __future__ import annotations

import dataclasses
import math


@dataclasses.dataclass(frozen=True)
class FabricPreset:
    """Material of one garment (isotropic thin shell).

    Attributes:
        name: preset name.
        density: areal density [kg/m²].
        stretch_stiffness: membrane Lamé μ (shear modulus × thickness) [N/m].
        area_stiffness: membrane Lamé λ (× thickness) [N/m].
        bend_stiffness: bending rigidity B of the continuum shell [N·m]; converted to
            per-edge dihedral stiffness with the discrete-shells scaling (see
            :func:`data_prep.simulate.scene.bending_stiffness_per_edge`).
        damping: stiffness-proportional (Rayleigh) damping time [s]: the damping
            coefficient of each membrane and bending element is ``damping × its
            stiffness``. 0 leaves only the integrator's own dissipation (and is ~1.5×
            faster: the damping terms are skipped).
        friction: Coulomb coefficient of fabric sliding on skin (effective value in the
            simulator, about half the measured dry one).
    """

    name: str
    density: float
    stretch_stiffness: float
    area_stiffness: float
    bend_stiffness: float
    damping: float
    friction: float

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            if field.name == "name":
                continue
            value = getattr(self, field.name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
                raise ValueError(f"fabric '{self.name}': {field.name} must be a finite "
                                 f"number >= 0, got {value!r}")
        if self.density <= 0 or self.stretch_stiffness <= 0:
            raise ValueError(f"fabric '{self.name}': density and stretch_stiffness must be "
                             "> 0")


# Cotton: SNUG's material (thickness 0.47 mm, 426 kg/m³, E = 0.7e5, ν = 0.485 → Lamé
# μ = 2.36e4, λ = 4.44e4, B = 3.96e-5 with its bending multiplier 50), reused by HOOD.
# Others: Blender preset ratios to cotton for stretch (silk 5/15, denim 40/15, leather
# 80/15); bending and density from measured ranges (Blender's bending ratios, ×20 for
# denim and ×300 for leather, would make leather a board). Damping stays ≪ dt (β = 1e-3 s
# broke the stretch gate for denim); friction is about half the measured skin–textile
# values, because penalty friction sticks the cloth in patches and crumples it.
# Measurements behind each choice: docs/simulation.md.
FABRICS: dict[str, FabricPreset] = {
    preset.name: preset
    for preset in (
        FabricPreset("silk", density=0.08, stretch_stiffness=7.9e3, area_stiffness=1.48e4,
                     bend_stiffness=4.0e-6, damping=0.0, friction=0.1),
        FabricPreset("cotton", density=0.20, stretch_stiffness=2.36e4,
                     area_stiffness=4.44e4, bend_stiffness=3.96e-5, damping=0.0,
                     friction=0.2),
        FabricPreset("denim", density=0.40, stretch_stiffness=6.3e4, area_stiffness=1.18e5,
                     bend_stiffness=3.0e-4, damping=1.0e-4, friction=0.25),
        FabricPreset("leather", density=0.90, stretch_stiffness=1.26e5,
                     area_stiffness=2.37e5, bend_stiffness=1.5e-3, damping=1.0e-4,
                     friction=0.3),
    )
}


def resolve_fabric(fabric: str | FabricPreset) -> FabricPreset:
    """The preset named ``fabric`` (case-insensitive), or ``fabric`` itself.

    Raises:
        ValueError: unknown name (the message lists the known ones).
    """
    if isinstance(fabric, FabricPreset):
        return fabric
    if not isinstance(fabric, str):
        raise ValueError(f"fabric must be a preset name or a FabricPreset, got {fabric!r}")
    preset = FABRICS.get(fabric.strip().lower())
    if preset is None:
        raise ValueError(f"unknown fabric '{fabric}'; known: {', '.join(FABRICS)}")
    return preset
