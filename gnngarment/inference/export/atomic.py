"""Atomic writes for exports: the library's single implementation
(:mod:`gnngarment.geometry.files`)."""

from gnngarment.geometry.files import TEMP_SUFFIX, atomic_write, atomic_write_bytes

__all__ = ["TEMP_SUFFIX", "atomic_write", "atomic_write_bytes"]
