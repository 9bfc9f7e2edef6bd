"""A contact sheet of sampled garments on Anny bodies (``docs/images/garments``).

    python -m data_prep.garments.contact_sheet [--out PATH] [--count 24] [--seed 0]
                                               [--synthetic] [--pipeline PATH]

Draws ``count`` garments (the types in turn, styles and resolutions at random) on a few
Anny body shapes in the T-pose, each over a light silhouette of its body, with the
garment's type, vertex count and one style detail as the caption.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from data_prep.garments.body_frame import BodyFrame
from data_prep.garments.garment import GARMENT_TYPES, Garment, sample_garment
from gnngarment.mesh_drawing import DrawnMesh, draw_meshes

#: Anny phenotypes the sheet cycles through (gender 0 = male, 1 = female).
PHENOTYPES: tuple[dict[str, float], ...] = (
    {"gender": 1.0, "age": 0.65},
    {"gender": 0.0, "age": 0.65, "height": 0.6},
    {"gender": 1.0, "age": 0.7, "weight": 0.85, "height": 0.35},
    {"gender": 0.0, "age": 0.8, "weight": 0.2, "muscle": 0.7},
)

GARMENT_RGB = (0.16, 0.42, 0.78)
BODY_RGB = (0.88, 0.86, 0.83)


def bodies(synthetic: bool = False) -> list[BodyFrame]:
    """The sheet's bodies: Anny phenotypes in the T-pose, or the synthetic body."""
    if synthetic:
        from data_prep.garments.synthetic_body import synthetic_body

        return [synthetic_body(0.0), synthetic_body(0.0, girth=1.2)]
    import anny

    from data_prep.garments.anny_frame import anny_body_frame

    model = anny.Anny()
    return [anny_body_frame(model, "T", phenotype) for phenotype in PHENOTYPES]


CAPTION_DETAIL = {
    "skirt": "flare {flare:.2f}, length {length:.2f}",
    "trousers": "length {length:.2f}, flare {flare:.2f}",
    "tshirt": "sleeve {sleeve_length:.2f}, {neckline} neck",
    "top": "{kind}, {neckline} neck",
    "dress": "{sleeves}, flare {flare:.2f}",
    "jumpsuit": "{sleeves}, length {length:.2f}",
}


def caption(garment: Garment) -> str:
    """Type, vertex count and the style's most telling details."""
    detail = CAPTION_DETAIL[garment.garment_type].format(**garment.style)
    return f"{garment.garment_type}, {garment.num_vertices} vertices\n{detail}"


def _save_small(figure: object, path: Path, dpi: int) -> None:
    """Save through Pillow with a 64-colour palette: ~150 KB instead of ~800 KB."""
    import io

    import matplotlib.pyplot as plt
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    buffer = io.BytesIO()
    figure.savefig(buffer, dpi=dpi, format="png")  # type: ignore[attr-defined]
    plt.close(figure)  # type: ignore[arg-type]
    image = Image.open(buffer).convert("RGB").quantize(colors=64, method=Image.Quantize.MEDIANCUT)
    image.save(path, optimize=True)


def render(garments: list[tuple[Garment, BodyFrame]], path: Path, columns: int = 6) -> None:
    """Draw the garments on a grid (3/4 front view) and save a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = int(np.ceil(len(garments) / columns))
    figure, axes = plt.subplots(rows, columns, figsize=(2.1 * columns, 2.5 * rows))
    for ax in np.ravel(axes):
        ax.set_axis_off()
    for ax, (garment, body) in zip(np.ravel(axes), garments, strict=False):
        # Crop the body to the garment's height range (plus a margin) so it stays large.
        draw_meshes(ax, [DrawnMesh(garment.pos, garment.faces, GARMENT_RGB),
                         DrawnMesh(body.vertices, body.faces, BODY_RGB, lit=False)],
                    azimuth_deg=25.0, elevation_deg=-8.0, edge_color=(0.05, 0.1, 0.2),
                    edge_width=0.05)
        ax.set_title(caption(garment), fontsize=6.5, pad=2)
    figure.subplots_adjust(left=0.01, right=0.99, top=0.96, bottom=0.01, wspace=0.02,
                           hspace=0.18)
    _save_small(figure, path, dpi=100)


def pipeline_figure(body: BodyFrame, path: Path, seed: int = 4) -> None:
    """The stages of one T-shirt: pattern, stitched panels, lifted start, final mesh."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from data_prep.garments import mesher
    from data_prep.garments.panel_boundary import trace
    from data_prep.garments.pattern import pair
    from data_prep.garments.silhouette import silhouette
    from data_prep.garments.tshirt import TShirtStyle, tshirt_outline

    design = tshirt_outline(body, TShirtStyle(sleeve_length=0.45, neckline="v",
                                                neck_depth=0.1)).design
    outline = pair(trace(design, silhouette(design), -1), trace(design, silhouette(design), 1))
    panels, lifted, _ = mesher.build_panels(design, 1200, np.random.default_rng(seed))
    final = mesher.mesh_design(design, body.distance, 1200, np.random.default_rng(seed))
    figure, axes = plt.subplots(1, 4, figsize=(12, 3.4))
    ax = axes[0]
    ax.plot(*body.vertices[::3][:, [0, 2]].T, ",", color="0.8")
    for run in outline.seams:
        ax.plot(*run.T, color="k", lw=1.5)
    for side, colour in ((-1, "tab:red"), (1, "tab:blue")):
        for run in outline.openings[side]:
            ax.plot(*run.T, color=colour, lw=1.2)
    ax.set_title("pattern: seams (black), front (red)\nand back (blue) openings", fontsize=8)
    ax = axes[1]
    front = panels.side <= 0
    keep = front[panels.faces].all(axis=1)
    ax.triplot(panels.xz[:, 0], panels.xz[:, 1], panels.faces[keep], lw=0.3, color="tab:red")
    ax.set_title("front panel, Delaunay\n(the back shares the seam points)", fontsize=8)
    for ax in axes[:2]:
        ax.set_aspect("equal")
        ax.set_axis_off()
    draw_meshes(axes[2], [DrawnMesh(lifted, panels.faces, GARMENT_RGB)], 60.0, -10.0,
                edge_color="k", edge_width=0.15)
    axes[2].set_title("lifted along Y (sparse at the folds)", fontsize=8)
    draw_meshes(axes[3], [DrawnMesh(final.pos, final.faces, GARMENT_RGB),
                          DrawnMesh(body.vertices, body.faces, BODY_RGB, lit=False)],
                60.0, -10.0, edge_color="k", edge_width=0.15)
    axes[3].set_title("relaxed on the surface, flipped, pushed out", fontsize=8)
    figure.tight_layout()
    _save_small(figure, path, dpi=90)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path,
                        default=Path("docs/images/garments/contact_sheet.png"))
    parser.add_argument("--count", type=int, default=24)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--synthetic", action="store_true", help="use the synthetic body")
    parser.add_argument("--pipeline", type=Path, default=None,
                        help="also draw the meshing stages of one T-shirt to this PNG")
    args = parser.parse_args(argv)
    shapes = bodies(args.synthetic)
    if args.pipeline is not None:
        pipeline_figure(shapes[0], args.pipeline)
    rng = np.random.default_rng(args.seed)
    types = sorted(GARMENT_TYPES)
    garments, times = [], []
    for i in range(args.count):
        body = shapes[i % len(shapes)]
        start = time.process_time()
        garment = sample_garment(body, rng, types[i % len(types)])
        times.append(time.process_time() - start)
        garments.append((garment, body))
    render(garments, args.out)
    sizes = [g.num_vertices for g, _ in garments]
    print(f"{len(garments)} garments, {min(sizes)}–{max(sizes)} vertices, median generation "
          f"{np.median(times):.2f} s CPU → {args.out} ({args.out.stat().st_size // 1024} KB)")


if __name__ == "__main__":
    main()
