"""Atomic file writes for the attribution outputs (PNG, PLY, JSON): the library's single
implementation (:mod:`gnngarment.geometry.files`; permissions follow the umask)."""

from gnngarment.geometry.files import atomic_write_bytes as write_bytes_atomic

__all__ = ["write_bytes_atomic"]
