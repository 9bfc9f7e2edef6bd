"""How much the heading (rotation about the vertical) of mocap windows varies: the bound
on what heading-invariant motion inputs can change, measured before building them.

The LSTM encoders read world-frame inputs (the root's axis-angle and displacement, body
vertex velocities). Inputs in the body's heading frame would make a walk towards −Y and
one towards +X look alike; that only matters if the motions do face different ways. For
every clip in the folder (after dropping its T-pose reference frame and resampling to
``--fps``) this prints the heading of its first frame, the root's tilt from upright plus
heading (the root rotation's angle), and the largest heading change within any window of
``--window`` seconds (every quarter window), then the median absolute first heading.

    .venv/bin/python benchmarks/clip_headings.py [--clips ../shared/real-world/motions/cmu]

Heading = the angle of the root's x axis in the ground plane (Z up), in degrees.
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from gnngarment.body.lead_in import trim_reference_pose
from gnngarment.body.motion_io import load_motion


def headings(root_rotations: np.ndarray) -> np.ndarray:
    """Unwrapped heading (radians) of root axis-angles ``(T, 3)`` → ``(T,)``."""
    matrix = Rotation.from_rotvec(root_rotations).as_matrix()
    return np.unwrap(np.arctan2(matrix[:, 1, 0], matrix[:, 0, 0]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--clips", default="../shared/real-world/motions/cmu")
    parser.add_argument("--fps", type=float, default=30.0)
    parser.add_argument("--window", type=float, default=2.0, help="seconds")
    args = parser.parse_args()
    first = []
    for path in sorted(Path(args.clips).glob("*.bvh")):
        with warnings.catch_warnings():  # unmapped fingers: `inspect` says so
            warnings.simplefilter("ignore")
            motion = trim_reference_pose(load_motion(path)).resample(args.fps)
        heading = headings(motion.rotations[:, 0])
        frames = round(args.window * args.fps)
        step = max(frames // 4, 1)
        turns = [abs(heading[i + frames] - heading[i])
                 for i in range(0, len(heading) - frames, step)] or [0.0]
        tilt = np.degrees(np.linalg.norm(motion.rotations[0, 0]))
        first.append(abs((np.degrees(heading[0]) + 180) % 360 - 180))
        print(f"{path.name}: first heading {np.degrees(heading[0]):7.1f}°, root angle "
              f"{tilt:6.1f}°, largest turn in {args.window:g} s {np.degrees(max(turns)):6.1f}°, "
              f"{len(motion) / args.fps:5.1f} s")
    first = np.asarray(first)
    print(f"{len(first)} clips: median |first heading| {np.median(first):.1f}°, "
          f"{int((first > 45).sum())} beyond 45°")


if __name__ == "__main__":
    main()
