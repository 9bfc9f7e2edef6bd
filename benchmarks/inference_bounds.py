"""The fastest the shipped network can run on this CPU: its dense matrix products at the
CPU's measured matmul peak, with everything else free — the bound on issue 39's
"≥ 200× Newton at batch 16", measured before a further attempt at the attention.

The fused attention operator made the attention no longer the wall at batch 16; the
profile's largest part is now ``aten::mm``, the GAT layers' dense projections. Those are
already one BLAS call each, so no fusion makes them cheaper: their floating-point
operations divided by the best rate this CPU's BLAS reaches bound the network's time from
below. This script, in one run:

1. counts the dense matrix-product FLOPs of one forward of the shipped model (as
   ``animate`` runs it) on a ``--vertices``-vertex flared skirt at batch ``--batch``
   (every ``mm``, ``addmm`` and ``bmm`` on strided tensors; the LSTMs, which run as one
   oneDNN operator, the sparse pooling products and the attention's per-edge work are
   left out, which only makes the bound looser);
2. measures this CPU's float32 matmul rate at ``--threads`` threads: the best of
   ``--repeats`` runs of a square 2048 product and of the first projection's own shape,
   the faster taken (the more generous the rate, the safer the bound);
3. times the forward itself (best of ``--repeats``), the products' own time inside one
   profiled forward (so how far from the peak they run), and Newton on the same garment
   (``inference_speed.measure_simulator``);

and prints the frames/s the dense products alone allow and their ratio to Newton. If that
cap is below 200× Newton, no operator for the attention (or for anything else) reaches
the target at this network's width on this CPU.

    OMP_NUM_THREADS=2 .venv/bin/python benchmarks/inference_bounds.py [--vertices 5000]
        [--batch 16] [--threads 2] [--repeats 7] [--simulator-frames 30]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import torch
from torch.profiler import ProfilerActivity, profile
from torch.utils._python_dispatch import TorchDispatchMode

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "benchmarks"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

from inference_speed import frame_inputs, make_pair, measure_simulator  # noqa: E402

from benchmarks.machine import cpu_model  # noqa: E402
from data_prep.garments.skirt import flared_skirt  # noqa: E402
from gnngarment.model.checkpoint import load_model  # noqa: E402
from gnngarment.model.fused_attention import attention_path  # noqa: E402
from gnngarment.paths import SHIPPED_MODEL  # noqa: E402

#: Issue 39's target: frames/s at batch 16 over Newton's.
TARGET_RATIO = 200.0


class DenseMatmulCounter(TorchDispatchMode):
    """FLOPs (2 per multiply-add) of the dense matrix products run under it, and the
    shapes ``(m, k, n)`` of each; products with a sparse operand are not counted."""

    def __init__(self):
        super().__init__()
        self.flops = 0
        self.shapes: list[tuple[int, int, int]] = []

    def __torch_dispatch__(self, func, types, args=(), kwargs=None):
        out = func(*args, **(kwargs or {}))
        packet = func.overloadpacket
        operands = {torch.ops.aten.mm: args[:2], torch.ops.aten.addmm: args[1:3],
                    torch.ops.aten.bmm: args[:2]}.get(packet)
        if operands is not None and all(t.layout == torch.strided for t in operands):
            a, b = operands
            batch = a.shape[0] if a.dim() == 3 else 1
            m, k, n = a.shape[-2], a.shape[-1], b.shape[-1]
            self.flops += 2 * batch * m * k * n
            self.shapes.append((batch * m, k, n))
        return out


def matmul_rate(m: int, k: int, n: int, repeats: int) -> float:
    """Best float32 GFLOP/s of an ``(m, k) @ (k, n)`` product over ``repeats`` runs."""
    generator = torch.Generator().manual_seed(0)
    a = torch.randn(m, k, generator=generator)
    b = torch.randn(k, n, generator=generator)
    a @ b
    best = float("inf")
    for _ in range(repeats):
        tic = time.perf_counter()
        a @ b
        best = min(best, time.perf_counter() - tic)
    return 2 * m * k * n / best / 1e9


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--vertices", type=int, default=5000)
    parser.add_argument("--batch", type=int, default=16)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--simulator-frames", type=int, default=30,
                        help="frames Newton simulates for its rate (0: skip it)")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    model = load_model(SHIPPED_MODEL).eval()
    pos, faces = flared_skirt(args.vertices)
    pair = make_pair(pos, faces, model.config)
    print(f"{cpu_model()}, {args.threads} threads, load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores; shipped model ({SHIPPED_MODEL.name}), {len(pos)}-vertex "
          f"flared skirt, batch {args.batch}", flush=True)
    inputs = frame_inputs(model.config, args.batch)
    counter = DenseMatmulCounter()
    # Counted under no_grad, not inference_mode: there the dispatcher still decomposes
    # matmul and linear into the mm / addmm the counter sees.
    with torch.no_grad():
        context = model.encode([pair])
        model(context, *inputs)                       # builds the batch's graph structures
        with counter:
            model(context, *inputs)
    with torch.inference_mode():
        context = model.encode([pair])
        model(context, *inputs)
        forward = float("inf")
        for _ in range(args.repeats):
            tic = time.perf_counter()
            model(context, *inputs)
            forward = min(forward, time.perf_counter() - tic)
        with profile(activities=[ProfilerActivity.CPU]) as profiled:
            model(context, *inputs)
    in_forward = sum(event.self_cpu_time_total for event in profiled.key_averages()
                     if event.key in ("aten::mm", "aten::addmm", "aten::bmm")) / 1e6
    largest = max(counter.shapes, key=lambda s: s[0] * s[1] * s[2])
    rates = {"square 2048": matmul_rate(2048, 2048, 2048, args.repeats),
             f"largest projection {largest}": matmul_rate(*largest, args.repeats)}
    peak = max(rates.values())
    floor = counter.flops / (peak * 1e9)
    print(f"dense matrix products of one forward: {counter.flops / 1e9:.2f} GFLOP in "
          f"{len(counter.shapes)} products (largest {largest[0]}×{largest[1]} @ "
          f"{largest[1]}×{largest[2]}); attention path {attention_path()}")
    for name, rate in rates.items():
        print(f"matmul rate, {name}: {rate:.1f} GFLOP/s")
    print(f"forward at the peak rate ({peak:.1f} GFLOP/s), dense products only: "
          f"{floor * 1000:.1f} ms = {args.batch / floor:.0f} frames/s at most")
    print(f"dense products inside one profiled forward: {in_forward * 1000:.1f} ms of "
          f"self time (sparse ones included) = {counter.flops / in_forward / 1e9:.1f} "
          "GFLOP/s")
    print(f"forward measured (best of {args.repeats}): {forward * 1000:.1f} ms = "
          f"{args.batch / forward:.1f} frames/s; the dense floor is "
          f"{floor / forward:.0%} of it")
    if args.simulator_frames:
        newton = measure_simulator(pos, faces, args.simulator_frames)
        if newton:
            cap = args.batch / floor / newton
            print(f"Newton {newton:.2f} frames/s: measured forward "
                  f"{args.batch / forward / newton:.0f}×, dense-product cap {cap:.0f}× "
                  f"(target {TARGET_RATIO:.0f}×: "
                  f"{'within the cap' if cap >= TARGET_RATIO else 'above the cap'})")


if __name__ == "__main__":
    main()
