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


#: Most values a YAML document may expand to (aliases counted each time they are used):
#: a "billion laughs" file of a few lines expands to millions.
MAX_YAML_VALUES = 100_000
#: Deepest nesting of a YAML document (our configs nest three levels).
MAX_YAML_DEPTH = 64


def parse_yaml(text: str, source: str) -> Any:
    """The value of a YAML document, as plain Python (dicts, lists, scalars), read safely:
    no tags that build objects (``!!python/...``), no duplicate keys, at most
    :data:`MAX_YAML_DEPTH` levels and :data:`MAX_YAML_VALUES` values after alias
    expansion.

    Raises:
        ConfigError: one line naming ``source`` (the file), the problem and its line.
    """
    import yaml

    class StrictLoader(yaml.SafeLoader):
        """SafeLoader that refuses a key given twice (PyYAML keeps the last)."""

        def construct_mapping(self, node, deep=False):  # type: ignore[no-untyped-def]
            seen: dict[Any, Any] = {}
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=deep)
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key '{key}'", key_node.start_mark)
                seen[key] = True
            return super().construct_mapping(node, deep=deep)

    try:
        value = yaml.load(text, Loader=StrictLoader)  # a SafeLoader subclass: no object tags
    except yaml.MarkedYAMLError as error:
        problem = error.problem or error.context or "invalid YAML"
        mark = error.problem_mark or error.context_mark
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
        if problem.startswith("could not determine a constructor"):
            problem = "a tag that would build an object is not allowed " + problem[
                problem.find("for the tag"):].removeprefix("for the tag ")
        raise ConfigError(f"{source}: not a valid YAML file: {problem}{where}") from None
    except yaml.YAMLError as error:
        raise ConfigError(f"{source}: not a valid YAML file: "
                          f"{str(error).splitlines()[0]}") from None
    except RecursionError:
        raise ConfigError(f"{source}: YAML nested too deeply "
                          f"(at most {MAX_YAML_DEPTH} levels)") from None
    _check_yaml_size(value, source)
    return value


def _check_yaml_size(value: Any, source: str) -> None:
    """Walk the expanded document with a budget (aliases share objects, so the walk
    counts what a copy would build) and refuse one too deep or too large."""
    budget = MAX_YAML_VALUES
    stack = [(value, 1)]
    while stack:
        item, depth = stack.pop()
        budget -= 1
        if budget < 0:
            raise ConfigError(f"{source}: YAML expands to more than {MAX_YAML_VALUES:,} "
                              "values (aliases repeated inside aliases?)")
        if depth > MAX_YAML_DEPTH:
            raise ConfigError(f"{source}: YAML nested too deeply "
                              f"(at most {MAX_YAML_DEPTH} levels)")
        if isinstance(item, dict):
            stack.extend((child, depth + 1) for pair in item.items() for child in pair)
        elif isinstance(item, list):
            stack.extend((child, depth + 1) for child in item)


def parse_mapping_text(text: str, suffix: str, source: str = "<text>") -> Any:
    """The value of a small user file (a body shape, a joint map): JSON for ``.json``,
    YAML (:func:`parse_yaml`: no code execution, no duplicate keys) for ``.yaml``/``.yml``.

    Raises:
        KeyError: ``suffix`` is not one of :data:`MAPPING_SUFFIXES`.
        ConfigError: a YAML problem, naming ``source``.
        ValueError: a JSON syntax error or duplicate key (callers name their file).
    """
    import json

    suffix = suffix.lower()
    if suffix == ".json":
        def refuse_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
            keys = [key for key, _ in pairs]
            repeated = sorted({key for key in keys if keys.count(key) > 1})
            if repeated:
                raise ValueError(f"duplicate key(s) {repeated}")
            return dict(pairs)

        return json.loads(text, object_pairs_hook=refuse_duplicates)
    if suffix in (".yaml", ".yml"):
        return parse_yaml(text, source)
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
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise ConfigError(f"{path}: cannot read the config file ({error})") from None
    value = parse_yaml(text, str(path))
    if value is not None and not isinstance(value, (dict, list)):
        # OmegaConf.create would parse a string as YAML text again.
        raise ConfigError(f"{path}: expected a mapping of settings, got a "
                          f"{type(value).__name__}")
    try:
        return OmegaConf.create(value if value is not None else {})
    except Exception as error:  # a scalar document, a key OmegaConf cannot hold
        raise ConfigError(f"{path}: not a config ({str(error).splitlines()[0]})") from None


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
