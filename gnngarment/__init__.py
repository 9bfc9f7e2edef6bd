"""gnngarment: one learned model that animates any garment mesh on any body for any motion."""

__version__ = "0.3.0"
