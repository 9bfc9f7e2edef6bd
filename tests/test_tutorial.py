"""docs/tutorial.md runs: its ``python`` blocks, in order, in one namespace, in a
temporary folder (the page promises it works with this version)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

TUTORIAL = Path(__file__).resolve().parents[1] / "docs" / "tutorial.md"


def python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_tutorial_has_code():
    assert len(python_blocks(TUTORIAL.read_text())) >= 5


def test_tutorial_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "tutorial"}
    for index, block in enumerate(python_blocks(TUTORIAL.read_text())):
        try:
            exec(compile(block, f"{TUTORIAL}:block{index + 1}", "exec"), namespace)
        except Exception as error:  # name the block that broke
            pytest.fail(f"tutorial block {index + 1} failed: {error!r}\n{block}")
    out = tmp_path / "tutorial_output"
    for name in ("animation/my_skirt.glb", "animation/my_skirt.pc2",
                 "attribution/attribution.png", "attribution/attribution.ply"):
        assert (out / name).is_file(), name
    assert namespace["animation"].posed.shape[0] == len(namespace["frames"].joint_transforms)
