"""One version: gnngarment/__init__.py, read by pyproject, the CLI and the changelog."""

from __future__ import annotations

import re
from pathlib import Path

from typer.testing import CliRunner

from gnngarment import __version__
from gnngarment.cli import app
from gnngarment.model.checkpoint import CONTENT_HASH_KEY, load_checkpoint
from gnngarment.paths import REPOSITORY_ROOT, SHIPPED_MODEL


def test_version_names_the_release_and_the_shipped_model() -> None:
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0, result.output
    model_id = load_checkpoint(SHIPPED_MODEL)[CONTENT_HASH_KEY][:12]
    assert result.output.strip().endswith(
        f"gnngarment {__version__}; shipped model {SHIPPED_MODEL.name} {model_id}")


def test_the_changelog_and_pyproject_agree_with_the_package() -> None:
    changelog = (REPOSITORY_ROOT / "CHANGELOG.md").read_text()
    releases = re.findall(r"^## \[(\d+\.\d+\.\d+)\]", changelog, flags=re.MULTILINE)
    assert releases and releases[0] == __version__, releases
    model_id = load_checkpoint(SHIPPED_MODEL)[CONTENT_HASH_KEY][:12]
    latest = changelog.split("\n## [")[1]
    assert model_id in latest, "the latest release names the shipped model's id"
    pyproject = Path(REPOSITORY_ROOT / "pyproject.toml").read_text()
    assert 'dynamic = ["version"]' in pyproject
    assert 'version = {attr = "gnngarment.__version__"}' in pyproject
