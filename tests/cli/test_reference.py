"""docs/cli.md is what docs/build_cli_reference.py generates from the CLI (regenerate
it with that script after changing a command)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_cli_reference_is_current():
    spec = importlib.util.spec_from_file_location("build_cli_reference",
                                                  ROOT / "docs" / "build_cli_reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    expected = module.reference()
    assert "## `gnngarment animate`" in expected and "`--fix-units`" in expected
    committed = (ROOT / "docs" / "cli.md").read_text()
    assert committed == expected, ("docs/cli.md is out of date: run "
                                   "`.venv/bin/python docs/build_cli_reference.py`")
