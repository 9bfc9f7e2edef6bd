"""Zip the Blender add-on for *Edit → Preferences → Add-ons → Install from Disk*.

    python integrations/blender/build_zip.py [OUT.zip]     # default: ./gnngarment_import.zip

The zip holds ``gnngarment_import/__init__.py`` and ``gnngarment_import/manifest.py``
(no ``__pycache__``). Standard library only; any Python 3.8+ runs it.
"""

from __future__ import annotations

import sys
import zipfile
from pathlib import Path

ADDON = Path(__file__).resolve().parent / "gnngarment_import"


def build_zip(out: str | Path = "gnngarment_import.zip") -> Path:
    """Write the add-on zip to ``out`` and return its path."""
    out = Path(out)
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as archive:
        for path in sorted(ADDON.glob("*.py")):
            archive.write(path, f"{ADDON.name}/{path.name}")
    return out


if __name__ == "__main__":
    print(build_zip(*sys.argv[1:2]))
