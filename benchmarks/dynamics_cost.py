"""What the oscillator dynamics cost at inference, next to the network they are added to.

The shipped network's weights (``models/gnngarment-small.pt``) with ``dynamics_modes``
oscillator modes per vertex (their head's output weights made non-zero, so the work is
the trained model's), on a ``--vertices`` skirt, batches of ``--frames`` frames as
``animate`` runs them: the time of one forward pass without dynamics, and of the
dynamics' part of a pass (:class:`~gnngarment.model.deformer.DynamicsStream`: the drive
from the body-skinning frames and the carried recursion of every mode), each the best of
``--repeats`` interleaved runs, and their ratio — the issue's bar is ≤ 10 %. The modes'
parameters are computed once per garment (with the context), and timed apart.

    OMP_NUM_THREADS=1 .venv/bin/python benchmarks/dynamics_cost.py [--vertices 5000]
        [--frames 16] [--modes 4] [--repeats 7]
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import torch

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "benchmarks"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

from inference_speed import frame_inputs, make_pair  # noqa: E402

from benchmarks.machine import cpu_model  # noqa: E402
from data_prep.garments.skirt import flared_skirt  # noqa: E402
from gnngarment.model import GarmentDeformer  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--vertices", type=int, default=5000)
    parser.add_argument("--frames", type=int, default=16)
    parser.add_argument("--modes", type=int, default=4)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()

    shipped = load_model(SHIPPED_MODEL)
    model = GarmentDeformer(replace(shipped.config, dynamics_modes=args.modes))
    model.load_state_dict(shipped.state_dict(), strict=False)
    with torch.no_grad():
        output = model.oscillator_head.output
        output.weight.normal_(0.0, 0.3, generator=torch.Generator().manual_seed(0))
    model.eval()
    pos, faces = flared_skirt(args.vertices)
    pair = make_pair(pos, faces, model.config)
    motion, velocity, transforms = frame_inputs(model.config, args.frames)
    fps = 30.0
    with torch.inference_mode():
        context = model.encode([pair])
        tic = time.perf_counter()
        stream = model.dynamics_stream(context, fps)
        parameters_s = time.perf_counter() - tic
        zeros = torch.zeros(args.frames * len(pos), 3)
        network, dynamics = [], []
        for _ in range(args.repeats + 1):   # the first round warms up
            tic = time.perf_counter()
            model(context, motion, velocity, transforms, zeros)
            network.append(time.perf_counter() - tic)
            tic = time.perf_counter()
            stream.advance(transforms[0])
            dynamics.append(time.perf_counter() - tic)
    network_s, dynamics_s = min(network[1:]), min(dynamics[1:])
    print(f"{cpu_model()}, torch {torch.__version__}, {torch.get_num_threads()} thread(s); "
          f"{len(pos)}-vertex skirt, batch {args.frames}, {args.modes} modes per vertex")
    print(f"network pass        {1000 * network_s:8.1f} ms  (best of {args.repeats})")
    print(f"dynamics per pass   {1000 * dynamics_s:8.1f} ms  "
          f"({100 * dynamics_s / network_s:.1f} % of the network; bar <= 10 %)")
    print(f"modes per garment   {1000 * parameters_s:8.1f} ms  (once, with the context)")


if __name__ == "__main__":
    main()
