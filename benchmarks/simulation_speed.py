"""Speed and quality of the reference cloth simulation on a walking Anny body.

A flared skirt (waist ring pinned, irregular triangulation) at ~2k and ~5k vertices is
simulated around Anny's default body walking in place (procedural gait: hips, knees and
arms swing, eased in from the rest pose), then seconds per frame, the first-frame cost
(kernel compilation on an empty Warp cache) and the quality gates are printed. Also
times the per-frame inside/outside test (Warp vs trimesh) and can draw a few frames.

    .venv/bin/python benchmarks/simulation_speed.py [--sizes 2000 5000] [--frames 60]
        [--fabric cotton] [--figure docs/images/simulation/skirt_walk.png] [--check-inside]

Warp's CPU kernels use one core: a dataset builder should run one simulation process
per core.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from data_prep.garments import flared_skirt
from data_prep.simulate import SimulationSettings, simulate_garment
from gnngarment.geometry.graph import largest_component
from gnngarment.geometry.normals import face_normals
from gnngarment.mesh_drawing import DrawnMesh, draw_meshes

#: Stride period of the procedural walk [s] and the time its amplitude eases in over [s].
STRIDE_PERIOD = 1.1
EASE_IN = 0.5


def _rot_x(angle: np.ndarray) -> np.ndarray:
    """``(T, 4, 4)`` rotations about +X by ``angle`` ``(T,)`` [rad]."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.tile(np.eye(4), (len(angle), 1, 1))
    out[:, 1, 1], out[:, 1, 2], out[:, 2, 1], out[:, 2, 2] = c, -s, s, c
    return out


def anny_walk(num_frames: int, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Anny's default body walking in place, Z-up, metres.

    Returns:
        vertices ``(T, N_b, 3)`` float64 (frame 0 is the rest pose) and faces
        ``(F_b, 3)`` of the body's largest (closed) component.
    """
    from data_prep.simulate._backend import import_warp

    import_warp()  # quiet, before Anny initialises Warp on import and prints its banner
    import anny
    import torch

    model = anny.Anny()
    model.eval()
    labels = list(model.bone_labels)
    t = np.arange(num_frames) / fps
    phase = 2 * np.pi * t / STRIDE_PERIOD
    ease = np.clip(t / EASE_IN, 0, 1) ** 2 * (3 - 2 * np.clip(t / EASE_IN, 0, 1))
    pose = np.tile(np.eye(4), (num_frames, len(labels), 1, 1))
    for side, sign in (("L", 1.0), ("R", -1.0)):
        # +X rotation swings a hanging limb backwards (NOTES.md); the knee flexes while
        # its leg swings forward; arms swing against the legs.
        hip = -sign * 0.45 * np.sin(phase) * ease
        knee = 0.6 * np.maximum(0.0, sign * np.cos(phase)) * ease
        pose[:, labels.index(f"upperleg01.{side}")] = _rot_x(hip)
        pose[:, labels.index(f"lowerleg01.{side}")] = _rot_x(knee)
        pose[:, labels.index(f"upperarm01.{side}")] = _rot_x(-0.6 * hip)
    with torch.no_grad():
        out = model(pose_parameters=torch.tensor(pose, dtype=torch.float32))
    vertices = out["vertices"].double().numpy()
    keep, faces = largest_component(model.faces.numpy().astype(np.int64),
                                     vertices.shape[1])
    return vertices[:, keep], faces


def skirt_on_anny(num_vertices: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A flared skirt hanging from Anny's natural waist (z = 0.12 m), 0.55 m long, its
    waist ring an ellipse just outside the body's (0.15 × 0.11 m, centred at y = −0.02).

    Returns:
        pos ``(N, 3)``, faces ``(F, 3)`` and the waist-ring vertex indices ``(P,)``.
    """
    waist_z = 0.12
    pos, faces = flared_skirt(num_vertices, waist_radius=0.15, hem_radius=0.42,
                              length=0.55, waist_height=waist_z, seed=0)
    pos = pos * np.array([1.0, 0.75, 1.0]) + np.array([0.0, -0.02, 0.0])
    ring = np.flatnonzero(pos[:, 2] > waist_z - 1e-9)
    return pos, faces, ring


def winding_number(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray,
                   chunk: int = 256) -> np.ndarray:
    """Generalised winding number ``(N,)`` of ``points`` w.r.t. a closed mesh (1 inside,
    0 outside; Van Oosterom–Strackee solid angles, O(N·F) numpy): an independent
    reference for the Warp inside test."""
    tri = vertices[faces]  # (F, 3, 3)
    total = np.empty(len(points))
    for start in range(0, len(points), chunk):
        r = tri[None] - points[start:start + chunk, None, None]  # (n, F, 3, 3)
        a, b, c = r[:, :, 0], r[:, :, 1], r[:, :, 2]
        la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
        numerator = np.einsum("nfi,nfi->nf", a, np.cross(b, c))
        denominator = (la * lb * lc + np.einsum("nfi,nfi->nf", a, b) * lc
                       + np.einsum("nfi,nfi->nf", b, c) * la
                       + np.einsum("nfi,nfi->nf", c, a) * lb)
        total[start:start + chunk] = 2 * np.arctan2(numerator, denominator).sum(axis=1)
    return total / (4 * np.pi)


def sharp_fold_fraction(pos: np.ndarray, faces: np.ndarray, degrees: float = 30.0) -> float:
    """Fraction of interior edges whose two faces' normals differ by more than
    ``degrees``: element-scale crumpling, which a smooth drape keeps near 0."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    face_of = np.tile(np.arange(len(faces)), 3)
    key = np.sort(edges, axis=1)
    order = np.lexsort((key[:, 1], key[:, 0]))
    key, face_of = key[order], face_of[order]
    shared = (key[1:] == key[:-1]).all(axis=1)
    normal = face_normals(pos, faces)
    cosine = np.einsum("ij,ij->i", normal[face_of[:-1][shared]], normal[face_of[1:][shared]])
    return float(np.mean(cosine < np.cos(np.radians(degrees))))


def time_inside_tests(body: np.ndarray, faces: np.ndarray, points: np.ndarray) -> None:
    """Print the cost of one frame's inside/outside test: the Warp kernel the simulator
    uses vs a numpy winding number (trimesh's ``contains`` needs rtree, not installed)."""
    from data_prep.simulate.inside import signed_distance

    signed_distance(points, body, faces)  # compile once
    tic = time.perf_counter()
    warp_inside = signed_distance(points, body, faces) < 0
    warp_seconds = time.perf_counter() - tic
    tic = time.perf_counter()
    reference_inside = winding_number(points, body, faces) > 0.5
    reference_seconds = time.perf_counter() - tic
    agree = np.mean(warp_inside == reference_inside)
    print(f"inside test, {len(points)} points vs {len(faces)} triangles: warp "
          f"{1e3 * warp_seconds:.1f} ms (incl. BVH build), numpy winding number "
          f"{1e3 * reference_seconds:.0f} ms; agreement {100 * agree:.2f}% "
          f"({warp_inside.sum()} vs {reference_inside.sum()} inside)")


def draw(body: np.ndarray, faces: np.ndarray, garment: np.ndarray,
         garment_faces: np.ndarray, frames: list[int], path: Path) -> None:
    """Front and side views of ``frames`` (body grey, garment blue), PNG at ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    views = (0.0, -90.0)  # azimuths: front (camera on −Y), side (camera on +X)
    fig, axes = plt.subplots(2, len(frames), figsize=(1.5 * len(frames), 4.4))
    for column, frame in enumerate(frames):
        for row, azimuth in enumerate(views):
            ax = axes[row, column]
            draw_meshes(ax, [DrawnMesh(body[frame], faces, (0.75, 0.72, 0.7)),
                             DrawnMesh(garment[frame], garment_faces, (0.25, 0.45, 0.85))],
                        azimuth, 0.0, limits=((-0.55, 0.55), (-0.9, 0.8)), antialiased=False)
            if row == 0:
                ax.set_title(f"frame {frame}", fontsize=8)
    fig.tight_layout(pad=0.2)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[2000, 5000])
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--fps", type=float, default=30.0)
    parser.add_argument("--fabric", default="cotton")
    parser.add_argument("--substeps", type=int, default=SimulationSettings.substeps)
    parser.add_argument("--iterations", type=int, default=SimulationSettings.iterations)
    parser.add_argument("--figure", type=Path, default=None,
                        help="draw a few frames of the first size to this PNG")
    parser.add_argument("--check-inside", action="store_true",
                        help="time the inside test against a numpy winding number (~1 min)")
    args = parser.parse_args()

    tic = time.perf_counter()
    body, body_faces = anny_walk(args.frames, args.fps)
    print(f"Anny walk: {args.frames} frames, {body.shape[1]} vertices, {len(body_faces)} "
          f"triangles ({time.perf_counter() - tic:.1f} s)")
    settings = SimulationSettings(substeps=args.substeps, iterations=args.iterations,
                                  max_retries=0)
    for index, size in enumerate(args.sizes):
        pos, faces, ring = skirt_on_anny(size)
        tic = time.perf_counter()
        result = simulate_garment(pos, faces, body, body_faces, args.fps, args.fabric,
                                  pinned=ring, settings=settings)
        wall = time.perf_counter() - tic
        quality = result.quality
        print(f"{len(pos)} vertices, {args.fabric}, {result.substeps} substeps × "
              f"{settings.iterations} iterations: {result.seconds_per_frame:.3f} s/frame "
              f"(CPU {result.cpu_seconds_per_frame:.3f} s), "
              f"setup + first frame {result.setup_seconds:.1f} s, total {wall:.1f} s for "
              f"{settings.settle_frames} settle + {args.frames - 1} frames; max stretch "
              f"{np.max(quality.max_stretch):.3f}, max inside "
              f"{100 * np.max(quality.inside_fraction):.2f}%, edges folded > 30° in the last "
              f"frame {100 * sharp_fold_fraction(result.positions[-1].astype(float), faces):.1f}%")
        if index == 0:
            if args.check_inside:
                time_inside_tests(body[-1], body_faces, result.positions[-1])
            if args.figure is not None:
                frames = [int(f) for f in np.linspace(0, args.frames - 1, 5)]
                draw(body, body_faces, result.positions, faces, frames, args.figure)
                print(f"figure: {args.figure}")


if __name__ == "__main__":
    main()
