"""The garment generator's recoverable failure, raised wherever a design turns out
unusable (the silhouette, the pattern, the parts sized from the body): the sampler
catches it and draws another design."""

from __future__ import annotations


class PatternError(ValueError):
    """The design does not give a usable pattern (e.g. two layers overlap in the frontal
    view, or a cut splits the garment); the sampler draws another design."""
