"""Dataset preparation: CLOTH3D reader, synthetic garments, reference simulation, cache."""
