"""Atomic writes for CLOTH3D files: the library's single implementation
(:mod:`gnngarment.geometry.files`)."""

from gnngarment.geometry.files import TEMP_SUFFIX, atomic_write, atomic_write_bytes

__all__ = ["TEMP_SUFFIX", "atomic_write", "atomic_write_bytes"]
