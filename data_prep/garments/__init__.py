"""Procedural garments (the synthetic CLOTH3D-like set's rest meshes)."""

from data_prep.garments.skirt import flared_skirt

__all__ = ["flared_skirt"]
