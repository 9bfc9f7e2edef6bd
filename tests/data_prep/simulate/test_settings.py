"""`SimulationSettings` and `load_simulation_settings` (no Newton run)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from data_prep.simulate import SimulationSettings, load_simulation_settings
from gnngarment.config import ConfigError
from gnngarment.paths import default_config


def test_shipped_yaml_equals_the_dataclass_defaults() -> None:
    loaded = load_simulation_settings(default_config("simulation.yaml"))
    assert dataclasses.asdict(loaded) == dataclasses.asdict(SimulationSettings())


@pytest.mark.parametrize("text,message", [
    ("substep: 3\n", "substep"),                   # typo: an error, not a new key
    ("substeps: many\n", "substeps"),              # wrong type
    ("substeps: 0\n", "substeps must be >= 1"),    # out of range
    ("max_inside_fraction: 2.0\n", "max_inside_fraction"),
])
def test_bad_settings_files_name_file_and_key(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "sim.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=rf"sim\.yaml.*{message}"):
        load_simulation_settings(path)
