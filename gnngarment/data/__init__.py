"""The prepared cache: file format, dataset, batching of mixed-size garments."""

from gnngarment.data.cache import (
    CACHE_FORMAT_VERSION,
    BodyRecord,
    CacheError,
    GarmentRecord,
    SequenceRecord,
    read_manifest,
    topology_key,
    verify_cache,
    write_body,
    write_garment,
    write_manifest,
    write_sequence,
    write_topology,
)
from gnngarment.data.dataset import PreparedDataset, TrainingBatch, window_indices

__all__ = [
    "CACHE_FORMAT_VERSION", "BodyRecord", "CacheError", "GarmentRecord", "PreparedDataset",
    "SequenceRecord", "TrainingBatch", "read_manifest", "topology_key", "verify_cache",
    "window_indices", "write_body", "write_garment", "write_manifest", "write_sequence",
    "write_topology",
]
