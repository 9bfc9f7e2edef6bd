"""How far a model moves a garment while the body is still in the rest pose.

A garment handed to ``animate`` is the template (DESIGN.md): at frame 0 of a procedural
motion the body is in the rest pose, so the right answer is the garment itself. The
earlier shipped model, trained on undraped templates, dropped a flared skirt by 12 cm
(mean) there. For a flared skirt built on the rest body (the ``--shape`` Anny body),
this prints the mean and max distance of the model's frame 0, and of the mean over the
motion's rest hold, from the garment — before and after collision resolution.

    .venv/bin/python benchmarks/rest_pose_drift.py [--checkpoint models/gnngarment-small.pt]
        [--motion walk] [--vertices 1500] [--seed 7]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from data_prep.garments import BodyFrame, make_garment  # noqa: E402
from gnngarment.body import AnnyBodyModel, AnnyShape, make_motion  # noqa: E402
from gnngarment.body.procedural import HOLD_SECONDS  # noqa: E402
from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs  # noqa: E402
from gnngarment.inference.animate import animate  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--checkpoint", type=Path, default=SHIPPED_MODEL)
    parser.add_argument("--motion", default="walk")
    parser.add_argument("--vertices", type=int, default=1500)
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    torch.set_num_threads(1)

    model = load_model(args.checkpoint)
    body_model = AnnyBodyModel()
    shape = AnnyShape()
    rest = body_model.rest(shape)
    frame = BodyFrame(vertices=rest.vertices.numpy(), faces=rest.faces,
                      joints=rest.joints.numpy())
    garment = make_garment(frame, "skirt", {"flare": 0.6, "length": 0.55},
                           target_vertices=args.vertices, seed=args.seed)
    motion = make_motion(args.motion, duration=1.0, seed=args.seed)
    body = body_shape_inputs(body_model, shape, model.config.body_vertices)
    frames = body_motion_inputs(body_model, shape, motion, model.config.body_vertices)
    animation = animate(model, garment.pos, garment.faces, body, frames)
    hold = max(1, int(HOLD_SECONDS * motion.fps))
    print(f"checkpoint {args.checkpoint}; flared skirt, {len(garment.pos)} vertices, "
          f"{args.motion} (rest pose held for {hold} frames)")
    outputs = {"network": getattr(animation, "raw_posed", animation.posed),
               "after collision resolution": animation.posed}
    for label, posed in outputs.items():
        distance = np.linalg.norm(posed[:hold] - garment.pos, axis=2)  # (hold, N)
        print(f"{label:>28}: frame 0 mean {1000 * distance[0].mean():.1f} mm, max "
              f"{1000 * distance[0].max():.1f} mm; rest hold mean "
              f"{1000 * distance.mean():.1f} mm")


if __name__ == "__main__":
    main()
