"""CPU seconds of two user-facing steps that once had timed unit tests: generating one
3,000-vertex garment (`make_garment`, validation included) and rendering the 60-frame GIF
preview of a 2k-vertex garment on a 13k-vertex body (`render_preview`). Prints each
figure against its target as a ratio (< 1: within target). CPU time, not wall time: a
shared machine stretches wall time several-fold.

    .venv/bin/python benchmarks/generation_and_preview_speed.py
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from data_prep.garments import make_garment
from data_prep.garments.synthetic_body import synthetic_body
from gnngarment.inference.export.preview import render_preview
from gnngarment.paths import REPOSITORY_ROOT

# The preview scene is the tests' synthetic animation (tests/ is not an installed package).
sys.path.insert(0, str(REPOSITORY_ROOT))
from tests.inference.animations import synthetic_animation

#: Targets (CPU seconds): the bounds the unit tests used to assert.
GENERATION_TARGET_S = 3.0
PREVIEW_TARGET_S = 10.0


def main() -> None:
    body = synthetic_body()
    make_garment(body, "tshirt", target_vertices=3000, seed=0)  # warm-up (imports)
    started = time.process_time()
    make_garment(body, "jumpsuit", {"sleeves": "sleeved"}, target_vertices=3000, seed=0)
    generation = time.process_time() - started
    print(f"garment generation (3,000-vertex jumpsuit): {generation:.2f} s CPU, "
          f"{generation / GENERATION_TARGET_S:.2f}x of the {GENERATION_TARGET_S:.0f} s target")

    animation = synthetic_animation(frames=60, rings=40, sections=50, body_rings=130,
                                    body_sections=104)
    with tempfile.TemporaryDirectory() as folder:
        started = time.process_time()
        render_preview(animation, Path(folder) / "p.gif", max_frames=60)
        preview = time.process_time() - started
    print(f"GIF preview (60 frames, {animation.body_vertices.shape[1]}-vertex body): "
          f"{preview:.2f} s CPU, {preview / PREVIEW_TARGET_S:.2f}x of the "
          f"{PREVIEW_TARGET_S:.0f} s target")


if __name__ == "__main__":
    main()
