"""Typed configuration: YAML files in ``configs/`` merged into dataclasses in strict mode.

Every component owns a small dataclass of settings (defaults live in ``configs/*.yaml``
and mirror the dataclass defaults). :func:`load_config` merges a YAML file onto the
dataclass schema with OmegaConf; an unknown key or a value of the wrong type is an error
that names the file and the key, never a silently added setting.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, TypeVar

T = TypeVar("T")


class ConfigError(ValueError):
    """A configuration file is missing, unreadable, or does not match its schema."""


#: Suffixes :func:`parse_mapping_text` reads.
MAPPING_SUFFIXES = (".json", ".yaml", ".yml")


def parse_mapping_text(text: str, suffix: str) -> Any:
    """The value of a small user file (a body shape, a joint map): JSON for ``.json``,
    YAML (OmegaConf, no code execution) for ``.yaml``/``.yml``.

    Raises:
        KeyError: ``suffix`` is not one of :data:`MAPPING_SUFFIXES`.
        Exception: the parser's own syntax error (callers name their file).
    """
    import json

    suffix = suffix.lower()
    if suffix == ".json":
        return json.loads(text)
    if suffix in (".yaml", ".yml"):
        from omegaconf import OmegaConf

        return OmegaConf.to_container(OmegaConf.create(text))
    raise KeyError(suffix)


def read_yaml(path: str | Path) -> Any:
    """The OmegaConf node of a YAML config file, before any schema is applied: the one
    place a config file is read (:func:`load_config`, the training loader's composition).

    Raises:
        ConfigError: the file is missing or not valid YAML (naming the file).
    """
    from omegaconf import OmegaConf

    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: config file not found")
    try:
        return OmegaConf.load(path)
    except Exception as error:  # yaml.YAMLError and friends
        raise ConfigError(f"{path}: not a valid YAML file ({error})") from error


def load_config(path: str | Path, schema: type[T], section: str | None = None) -> T:
    """Load ``path`` (YAML) into an instance of the dataclass ``schema``.

    Args:
        path: YAML file.
        schema: a dataclass type whose fields (and their defaults) define the valid keys.
        section: if given, only this top-level key of the file is used (a file may hold
            the settings of several components).

    Returns:
        An instance of ``schema`` with the file's values over the dataclass defaults.

    Raises:
        ConfigError: the file is missing or not valid YAML, a key is unknown, or a
            value has the wrong type; the message names the file and the key.
    """
    path = Path(path)
    loaded = read_yaml(path)
    if section is not None:
        if section not in loaded:
            raise ConfigError(f"{path}: missing section '{section}'")
        loaded = loaded[section]
    return merge_config(schema, loaded, source=str(path))


def merge_config(schema: type[T], values: Any, source: str = "<overrides>") -> T:
    """Merge a mapping (dict or OmegaConf node) onto ``schema`` in strict mode.

    Raises:
        ConfigError: unknown key or wrong value type, naming ``source``.
    """
    from omegaconf import DictConfig, OmegaConf
    from omegaconf.errors import OmegaConfBaseException

    if not dataclasses.is_dataclass(schema):
        raise TypeError(f"{schema!r} is not a dataclass")
    if values is not None and not isinstance(values, (dict, DictConfig)):
        # A YAML list or scalar: OmegaConf would raise a bare TypeError naming no file.
        raise ConfigError(f"{source}: expected a mapping of settings, got a "
                          f"{type(values).__name__.removesuffix('Config').lower()}")
    base = OmegaConf.structured(schema)
    OmegaConf.set_struct(base, True)  # unknown keys are errors (HOOD turns this off; we don't)
    try:
        merged = OmegaConf.merge(base, values if values is not None else {})
        result = OmegaConf.to_object(merged)
    except OmegaConfBaseException as error:
        key = getattr(error, "full_key", None) or getattr(error, "key", None)
        where = f" key '{key}'" if key else ""
        message = str(error).splitlines()[0]
        raise ConfigError(f"{source}:{where} {message}") from error
    except ConfigError:
        raise
    except ValueError as error:  # a range check of the schema's __post_init__ names the key
        raise ConfigError(f"{source}: {error}") from error
    return result  # type: ignore[return-value]
