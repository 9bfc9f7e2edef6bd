from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import pytest

from gnngarment.config import ConfigError, load_config
from gnngarment.geometry.body_collisions import CollisionSettings
from gnngarment.geometry.prepare import GarmentPreparationConfig
from gnngarment.paths import default_config


@dataclass
class Example:
    levels: int = 2
    width: float = 0.5


def test_values_override_defaults(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text("levels: 3\n")
    assert load_config(path, Example) == Example(levels=3, width=0.5)


@pytest.mark.parametrize("text,message", [
    ("levles: 3\n", "levles"),            # a typo is an error, not a new key
    ("levels: three\n", "levels"),       # wrong type
    ("levels: [1\n", "not a valid YAML"),
])
def test_bad_files_name_file_and_key(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=rf"bad\.yaml.*{message}"):
        load_config(path, Example)


def test_missing_file_and_section(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="absent.yaml: config file not found"):
        load_config(tmp_path / "absent.yaml", Example)
    path = tmp_path / "c.yaml"
    path.write_text("other: {levels: 1}\n")
    with pytest.raises(ConfigError, match="missing section 'model'"):
        load_config(path, Example, section="model")
    assert load_config(path, Example, section="other").levels == 1


def test_shipped_garment_yaml_equals_the_dataclass_defaults() -> None:
    loaded = load_config(default_config("garment.yaml"), GarmentPreparationConfig)
    assert asdict(loaded) == asdict(GarmentPreparationConfig())


def test_shipped_collisions_yaml_equals_the_dataclass_defaults() -> None:
    loaded = load_config(default_config("collisions.yaml"), CollisionSettings)
    assert asdict(loaded) == asdict(CollisionSettings())
