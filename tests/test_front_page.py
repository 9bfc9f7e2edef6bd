"""The README's "your own garment in three lines" run as written (only the garment file
is ours: a small skirt on the rest body), so the front page cannot go stale."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
import trimesh
from typer.testing import CliRunner

from data_prep.garments.skirt import flared_skirt
from gnngarment.cli import app

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def three_lines() -> list[list[str]]:
    """The commands of the README's "Your own garment in three lines" block."""
    section = README.read_text().split("## Your own garment in three lines", 1)[1]
    block = re.search(r"```bash\n(.*?)```", section, flags=re.S).group(1)
    commands = []
    for line in block.splitlines():
        words = shlex.split(line.split("#", 1)[0])
        if words:
            commands.append(words)
    return commands


def test_readme_starts_with_the_two_commands():
    text = README.read_text()
    first_block = re.search(r"```bash\n(.*?)```", text, flags=re.S).group(1)
    assert [line.split()[:2] for line in first_block.splitlines()] == [["make", "demo"],
                                                                      ["make", "test"]]


@pytest.mark.slow
def test_readme_three_lines_run(tmp_path, monkeypatch, anny_body):
    commands = three_lines()
    assert [words[1] for words in commands] == ["inspect", "animate", "attribute"]
    rest = anny_body.rest()
    pelvis = rest.joints[0].numpy()
    pos, faces = flared_skirt(600, waist_radius=0.17, hem_radius=0.3, length=0.4,
                              waist_height=pelvis[2] + 0.08, seed=1)
    pos[:, :2] += pelvis[:2]
    monkeypatch.chdir(tmp_path)
    trimesh.Trimesh(pos, faces, process=False).export(tmp_path / "my_skirt.obj")
    (tmp_path / "models").symlink_to(ROOT / "models")
    runner = CliRunner()
    for words in commands:
        assert words[0] == ".venv/bin/gnngarment"
        result = runner.invoke(app, words[1:])
        assert result.exit_code == 0, f"{shlex.join(words)}\n{result.output}"
    assert (tmp_path / "out" / "my_skirt.glb").is_file()
    assert (tmp_path / "out" / "my_skirt.pc2").is_file()
    assert (tmp_path / "out" / "my_skirt_export.json").is_file()
    assert list((tmp_path / "heat").glob("*.png"))
