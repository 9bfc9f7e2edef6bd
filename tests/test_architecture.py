"""docs/architecture.md's package tree names every module of the two packages, and only
modules that exist (so a module added, moved or deleted shows up in review)."""

from __future__ import annotations

import re

from gnngarment.paths import REPOSITORY_ROOT


def test_the_package_tree_lists_every_module() -> None:
    text = (REPOSITORY_ROOT / "docs" / "architecture.md").read_text()
    section = text.split("## The package tree (one line per module)", 1)[1].split("\n## ", 1)[0]
    listed = set(re.findall(r"^((?:gnngarment|data_prep)/\S+\.py)\s", section, re.MULTILINE))
    modules = {str(path.relative_to(REPOSITORY_ROOT))
               for package in ("gnngarment", "data_prep")
               for path in (REPOSITORY_ROOT / package).rglob("*.py")}
    assert sorted(modules - listed) == [], "modules missing from the tree"
    assert sorted(listed - modules) == [], "the tree names modules that do not exist"
