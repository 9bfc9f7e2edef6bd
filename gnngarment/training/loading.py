"""Compose a training config: the YAML file, an optional model-config file it names, and
command-line ``key=value`` overrides — all merged strictly. Files are read by
:func:`gnngarment.config.read_yaml` and merged by :func:`gnngarment.config.merge_config`,
the same as every other config; only the composition lives here."""

from __future__ import annotations

from pathlib import Path

from gnngarment.config import ConfigError, load_config, merge_config, read_yaml
from gnngarment.model.config import ModelConfig
from gnngarment.paths import REPOSITORY_ROOT
from gnngarment.training.config import TrainingConfig


def _resolve(path: str, relative_to: Path) -> Path:
    candidate = Path(path)
    if candidate.is_absolute():
        return candidate
    for base in (relative_to, REPOSITORY_ROOT, Path.cwd()):
        if (base / candidate).is_file():
            return base / candidate
    return relative_to / candidate


def load_training_config(path: str | Path, overrides: list[str] | None = None
                         ) -> TrainingConfig:
    """Read ``path`` into a :class:`TrainingConfig`.

    A top-level ``model_config: <file>`` key loads the model settings from that YAML
    (relative to the config's folder or the repository root); keys under ``model:`` in
    the training file then override them. ``overrides`` are OmegaConf dotlist entries
    such as ``epochs=3`` or ``model.levels=0``.

    Raises:
        ConfigError: unknown keys, wrong types, missing files (naming the file).
    """
    from omegaconf import OmegaConf

    path = Path(path)
    raw = OmegaConf.to_container(read_yaml(path), resolve=True) or {}
    if not isinstance(raw, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level")
    model_file = raw.pop("model_config", None)
    if model_file:
        model_path = _resolve(str(model_file), path.parent)
        load_config(model_path, ModelConfig)  # validates the file on its own, naming it
        from_file = OmegaConf.to_container(read_yaml(model_path))
        raw["model"] = OmegaConf.to_container(OmegaConf.merge(from_file, raw.get("model") or {}))
    try:
        dotlist = OmegaConf.to_container(OmegaConf.from_dotlist(list(overrides or [])))
    except Exception as error:
        raise ConfigError(f"bad override {overrides}: {error}") from error
    source = f"{path} (with --set {' '.join(overrides)})" if overrides else str(path)
    return merge_config(TrainingConfig, OmegaConf.merge(OmegaConf.create(raw), dotlist),
                        source=source)
