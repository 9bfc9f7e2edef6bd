from pathlib import Path

import pytest

from gnngarment.body.config import BodyConfig, load_body_config
from gnngarment.body.factory import create_body_model
from gnngarment.config import ConfigError

CONFIG = Path(__file__).resolve().parents[2] / "configs" / "body.yaml"


def test_yaml_mirrors_dataclass_defaults():
    assert load_body_config(CONFIG) == BodyConfig()


def test_unknown_key_is_an_error(tmp_path):
    # motion_window was a BodyConfig field no code read (the model's window is used).
    path = tmp_path / "body.yaml"
    path.write_text("motion_window: 10\n")
    with pytest.raises(ConfigError, match="body.yaml"):
        load_body_config(path)


def test_unknown_model():
    with pytest.raises(ValueError, match="unknown body model"):
        create_body_model(BodyConfig(model="mannequin"))
