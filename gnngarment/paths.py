"""Where the repository's default files live (configs shipped next to the package)."""

from __future__ import annotations

from pathlib import Path

#: The repository root (the folder holding ``configs/``) for an editable install.
REPOSITORY_ROOT = Path(__file__).resolve().parent.parent
CONFIG_DIRECTORY = REPOSITORY_ROOT / "configs"


def default_config(name: str) -> Path:
    """Path of ``configs/<name>``; the file may be absent in a non-editable install,
    in which case callers fall back to their dataclass defaults (which mirror it)."""
    return CONFIG_DIRECTORY / name

#: The pretrained checkpoint kept in the repository (trained by
#: ``gnngarment train --config configs/train/benchmark.yaml``; see models/README.md).
SHIPPED_MODEL = REPOSITORY_ROOT / "models" / "gnngarment-small.pt"
