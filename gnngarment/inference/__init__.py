"""Animate a garment and export the result."""

from gnngarment.inference.animate import Animation, animate, garment_pair

__all__ = ["Animation", "animate", "garment_pair"]
