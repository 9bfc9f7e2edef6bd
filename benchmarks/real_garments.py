"""Real garments made on other bodies, fitted onto ours and animated (issue 13).

For every garment of ``../shared/real-world/garments`` whose source body is in
``../shared/real-world/bodies``: fit it from that body onto the rest body
(``animate --source-body``, :func:`gnngarment.inference.placement.place_garment`),
animate it on a walk with the shipped (or a given) model, and print

* the fit: scale, registration error, seconds;
* the median garment–body distance on its source body, on our rest body after the fit,
  and on the walking body (mean over frames of the per-frame median), in mm;
* the share of garment vertices inside the walking body after collision resolution
  and in the network's raw output (%, mean over frames; inside = more than 2 mm deep,
  the nearest-point sign of a dense body sampling);
* the same share and the deepest vertex (mm, mean over frames of each frame's deepest)
  for the network's raw output and for **body skinning** of the same fitted garment
  (the body's weights transferred to it, no blend shapes: the baseline every user has);
* the largest share of any vertex's skinning weight on joints whose body region is more
  than 20 cm from it (far weight, :func:`~gnngarment.evaluation.metrics.far_joint_weight`).

Targets (issue 13): inside < 1 % after resolution; walking median distance within 1 cm
of the source-body distance.

    .venv/bin/python benchmarks/real_garments.py [--checkpoint PATH] [--motion walk|FILE]
        [--shared ../shared] [--images docs/images/real_garments]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from gnngarment.body import AnnyBodyModel, load_motion_for_body  # noqa: E402
from gnngarment.body.skinning import skin  # noqa: E402
from gnngarment.body.weight_transfer import transfer_body_weights  # noqa: E402
from gnngarment.data.body_inputs import body_motion_inputs, body_shape_inputs  # noqa: E402
from gnngarment.evaluation.metrics import far_joint_weight  # noqa: E402
from gnngarment.geometry.mesh_io import load_mesh  # noqa: E402
from gnngarment.inference.animate import animate  # noqa: E402
from gnngarment.inference.checks import _Surface  # noqa: E402
from gnngarment.inference.placement import place_garment  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402

#: Garment → the body it was modelled on (../shared/real-world/README.md).
SOURCE_BODIES = {
    "snug_tank": "smpl_female_tpose_vto_body",
    "snug_shorts": "smpl_female_tpose_vto_body",
    "snug_long_sleeve_top": "smpl_female_tpose_vto_body",
    "vto_dress": "smpl_female_tpose_vto_body",
    "ncs_tshirt": "ncs_smpl_female_neutral_body",
    "ncs_pants": "ncs_smpl_female_neutral_body",
    "ncs_mannequin_tshirt": "ncs_mannequin_body",
    "pbns_outfit_top_bottom": "pbns_body_restpose_from_mat",
}
#: Depth below the body surface that counts as inside (metres).
INSIDE_DEPTH = 0.002


def distances(pos: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Signed nearest-surface distance of ``pos (N, 3)`` to a body (negative inside)."""
    return _Surface(np.asarray(vertices, dtype=np.float64), faces).signed_distance(
        np.asarray(pos, dtype=np.float64))


def write_strip(animation, path: Path, frames: int = 4, size: int = 240) -> Path:
    """A PNG of ``frames`` evenly spaced frames side by side (garment red, body grey),
    from the library's own preview renderer."""
    import tempfile
    from dataclasses import replace

    from PIL import Image

    from gnngarment.inference.export import render_preview

    chosen = np.linspace(0, len(animation.posed) - 1, frames).round().astype(int)
    picked = replace(animation, posed=animation.posed[chosen],
                     body_vertices=animation.body_vertices[chosen],
                     weights=animation.weights[chosen],
                     blend_shapes=animation.blend_shapes[chosen],
                     joint_transforms=animation.joint_transforms[chosen],
                     raw_posed=None)
    with tempfile.TemporaryDirectory() as folder:
        gif = render_preview(picked, Path(folder) / "strip.gif", size=size,
                             max_frames=frames, supersample=2)
        image = Image.open(gif)
        tiles = []
        for index in range(frames):
            image.seek(index)
            tiles.append(image.convert("RGB").copy())
    strip = Image.new("RGB", (size * frames, size), "white")
    for index, tile in enumerate(tiles):
        strip.paste(tile, (index * size, 0))
    path.parent.mkdir(parents=True, exist_ok=True)
    strip.save(path, optimize=True)
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--checkpoint", type=Path, default=SHIPPED_MODEL)
    parser.add_argument("--motion", default="walk")
    parser.add_argument("--shared", type=Path, default=ROOT.parent / "shared")
    parser.add_argument("--frames-measured", type=int, default=10,
                        help="Frames (evenly spaced) measured per garment.")
    parser.add_argument("--images", type=Path, default=None,
                        help="Also write <garment>.png here: 4 frames of the walk.")
    args = parser.parse_args()
    torch.set_num_threads(1)
    real = args.shared / "real-world"
    if not real.is_dir():
        raise SystemExit(f"{real}: not found (the real-world garments are not on this machine)")
    model = load_model(args.checkpoint)
    body_model = AnnyBodyModel()
    shape = body_model.parse_shape("average")
    body = body_shape_inputs(body_model, shape, model.config.body_vertices)
    # A motion file is retargeted to the rest body's joints, as `gnngarment animate` does.
    motion = load_motion_for_body(args.motion, body_model, shape, fps=30.0)
    frames = body_motion_inputs(body_model, shape, motion, model.config.body_vertices)
    print(f"checkpoint {args.checkpoint}, motion {args.motion} ({len(frames.vertices)} frames)")
    print("| garment | vertices | fit s | registration mm | median distance mm: source | "
          "rest | walking | inside % resolved | inside % raw | inside % body skinning | "
          "deepest mm raw | deepest mm body skinning | far weight % max | animate s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for garment, source_name in SOURCE_BODIES.items():
        pos, faces = load_mesh(real / "garments" / f"{garment}.obj")
        source = load_mesh(real / "bodies" / f"{source_name}.obj")
        placed = place_garment(pos, faces, body, source_body=source)
        started = time.perf_counter()
        result = animate(model, placed.pos, faces, body, frames)
        seconds = time.perf_counter() - started
        source_distance = np.median(np.abs(distances(pos, *source)))
        rest_distance = np.median(np.abs(distances(result.rest_pos, body.rest_vertices,
                                                   body.faces)))
        chosen = np.linspace(0, len(frames.vertices) - 1, args.frames_measured).round()
        body_weights = transfer_body_weights(result.rest_pos, body.rest_vertices,
                                             body.skinning_weights)
        body_skinned = skin(torch.from_numpy(result.rest_pos).float(), None,
                            torch.from_numpy(body_weights).float(),
                            torch.from_numpy(result.joint_transforms).float()).numpy()
        walking, inside, raw_inside, skinned_inside, raw_deepest, skinned_deepest = \
            [], [], [], [], [], []
        for t in chosen.astype(int):
            resolved = distances(result.posed[t], frames.vertices[t], body.faces)
            raw = distances(result.raw_posed[t], frames.vertices[t], body.faces)
            skinned = distances(body_skinned[t], frames.vertices[t], body.faces)
            walking.append(np.median(np.abs(resolved)))
            inside.append(np.mean(resolved < -INSIDE_DEPTH))
            raw_inside.append(np.mean(raw < -INSIDE_DEPTH))
            skinned_inside.append(np.mean(skinned < -INSIDE_DEPTH))
            raw_deepest.append(max(0.0, -raw.min()))
            skinned_deepest.append(max(0.0, -skinned.min()))
        far = far_joint_weight(result.weights, result.rest_pos, body.rest_vertices,
                               body.skinning_weights)["max"]
        if args.images is not None:
            write_strip(result, args.images / f"{garment}.png")
        print(f"| {garment} | {len(pos)} | {placed.seconds['fit']:.1f} | "
              f"{1000 * placed.fitted.registration_error:.1f} | {1000 * source_distance:.1f} | "
              f"{1000 * rest_distance:.1f} | {1000 * np.mean(walking):.1f} | "
              f"{100 * np.mean(inside):.2f} | {100 * np.mean(raw_inside):.2f} | "
              f"{100 * np.mean(skinned_inside):.2f} | {1000 * np.mean(raw_deepest):.1f} | "
              f"{1000 * np.mean(skinned_deepest):.1f} | "
              f"{100 * far:.1f} | {seconds:.1f} |", flush=True)


if __name__ == "__main__":
    main()
