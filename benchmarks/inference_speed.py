"""Inference speed of the garment deformer on CPU, and its ratio to the simulator.

For ``configs/model/small.yaml`` and ``configs/model/paper.yaml`` on a ~5k-vertex flared
skirt (one garment–body pair, context prepared once), prints frames/s of the full
per-frame model (both LSTMs, M^mp, skinning) at each batch size under
``torch.inference_mode`` — with ``--physics checkpoint`` as ``gnngarment animate`` runs the
model (the shipped supervised-stage checkpoint uses only the supervised M^mp), with
``--physics on`` with both M^mp submodules (a model trained through the physics stage);
both by default, each with its own ratio line — for both GAT
implementations (``csr``: GraphAttention on its PyTorch path, ``fused``: GraphAttention on the
fused C++ operator of :mod:`gnngarment.model.fused_attention`, ``pyg``: GATConv), with:

* ``--attention fused csr``: the fused operator and its PyTorch fallback side by side in one
  child (same weights, interleaved), with the fused ÷ fallback frames/s ratio per batch and
  each one's ratio to the simulator (the child says which path ``fused`` really ran:
  ``pytorch`` with the reason when the operator could not be built);

* the peak resident memory of the measuring process (each config × implementation runs
  in its own child process, so its peak is its own);
* the csr runs with glibc's default malloc and with freed blocks kept for reuse
  (``kept``: :func:`gnngarment.allocator.keep_freed_memory`, what every ``gnngarment``
  command sets; ``tuned``: the same through ``MALLOC_TUNED`` environment variables):
  fresh multi-MB tensors otherwise pay page faults;
* with ``--compete``: all of it while a competing process keeps one core busy;
* where the time goes (LSTMs, processors, skinning, the rest) and the top operators;
* bf16 autocast (whole forward, and processors only): speed, the error of the posed
  vertices against float32 (max / mean, mm) and M^mp's relative error on unit-normal
  inputs. ``small`` uses the shipped trained checkpoint (``models/gnngarment-small.pt``,
  same network), ``paper`` freshly initialised weights;
* with ``--compile on``: ``torch.compile`` (inductor's CPU backend) of the csr model, per
  ``--compile-target`` (``model``: the whole per-frame forward; ``processors``: the two
  M^mp submodules; ``layers``: every GAT layer of them) and ``--compile-mode``, each
  variant in a child process of its own, timed interleaved with that child's eager csr
  runs: the first call (compile + run), frames/s, the ratio to eager and the max
  posed-vertex difference;
* with ``--onnx``: whether the supervised M^mp submodule exports to ONNX (both
  exporters; the reason when not) and, when ``onnxruntime`` is installed, its MatMul
  against torch's on M^mp's two largest dense projections, and a variant of the csr
  model whose M^mp projections run on onnxruntime (timed like the compiled ones);
* the Newton simulator's frames/s on the same skirt around a moving capsule, and the
  model ÷ simulator ratio.

    .venv/bin/python benchmarks/inference_speed.py [--vertices 5000] [--configs small paper]
        [--batches 1 16] [--attention csr pyg] [--malloc default kept tuned] [--repeats 5]
        [--compete]
        [--threads 1 2 auto]
        [--no-bf16] [--no-simulator] [--sim-frames 30]
        [--compile on] [--compile-target model processors layers]
        [--compile-mode default max-autotune-no-cudagraphs] [--compile-cache cold] [--onnx]

Timings are the best of ``--repeats`` runs after a warm-up run (the warm-up builds the
cached graph structures): other processes share this machine's two cores.
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path

import numpy as np
import torch

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from data_prep.garments.skirt import flared_skirt  # noqa: E402
from gnngarment.allocator import SWITCH as KEEP_FREED_MEMORY  # noqa: E402
from gnngarment.allocator import keep_freed_memory  # noqa: E402
from gnngarment.config import load_config  # noqa: E402
from gnngarment.data.pair import GarmentBodyPair  # noqa: E402
from gnngarment.data.vertex_features import garment_vertex_features  # noqa: E402
from gnngarment.geometry import GarmentPreparationConfig, prepare_garment  # noqa: E402
from gnngarment.model import GarmentDeformer, ModelConfig, stack_hierarchies  # noqa: E402
from gnngarment.model import deformer as deformer_module  # noqa: E402
from gnngarment.model.fused_attention import (  # noqa: E402
    attention_path,
    fallback_reason,
    use_attention_path,
)
from gnngarment.model.graph_attention import set_attention  # noqa: E402

#: glibc settings that keep freed large blocks in the heap: by default every tensor
#: over 128 KiB is mmap'ed and unmapped again, so each large temporary pays page faults
#: on first touch, which on this machine cost more than the arithmetic on it.
MALLOC_TUNED = {"MALLOC_MMAP_THRESHOLD_": str(2**40), "MALLOC_TRIM_THRESHOLD_": str(2**40)}

#: Components timed separately (attribute names of GarmentDeformer).
COMPONENTS = ("pose_encoder", "velocity_encoder", "supervised_processor", "physics_processor")


def make_pair(pos: np.ndarray, faces: np.ndarray, config: ModelConfig,
              seed: int = 0) -> GarmentBodyPair:
    """A garment–body pair as ``tests/model/pairs.make_pair`` builds it (synthetic joints,
    body distances, body skinning weights and joint distances: only shapes matter for
    speed)."""
    rng = np.random.default_rng(seed)
    joints = rng.normal(scale=0.3, size=(24, 3))
    prepared = prepare_garment(pos, faces, GarmentPreparationConfig(
        levels=config.levels, landmarks=config.landmarks))
    return GarmentBodyPair.from_arrays(
        pos, garment_vertex_features(pos, faces, joints), prepared.hierarchy,
        prepared.descriptor, rng.random((config.body_vertices, 24)),
        rng.dirichlet(np.ones(24), size=len(pos)), rng.uniform(0.0, 0.4, (len(pos), 24)))


def frame_inputs(config: ModelConfig, frames: int, seed: int = 0
                 ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Random motion / velocity windows and rigid joint transforms for one pair.

    Shapes: ``(1, B, m, 75)``, ``(1, B, m, 3 N_b')``, ``(1, B, 24, 4, 4)``.
    """
    generator = torch.Generator().manual_seed(seed)
    motion = torch.randn(1, frames, config.window, 75, generator=generator) * 0.2
    velocity = torch.randn(1, frames, config.window, 3 * config.body_vertices,
                           generator=generator) * 0.1
    transforms = torch.eye(4).repeat(1, frames, 24, 1, 1)
    angle = torch.rand(1, frames, 24, generator=generator)
    transforms[..., 0, 0] = torch.cos(angle)
    transforms[..., 0, 1] = -torch.sin(angle)
    transforms[..., 1, 0] = torch.sin(angle)
    transforms[..., 1, 1] = torch.cos(angle)
    transforms[..., :3, 3] = torch.randn(1, frames, 24, 3, generator=generator) * 0.05
    return motion, velocity, transforms


def peak_rss_mb() -> float:
    """Peak resident set size of this process [MB] (Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


class ComponentTimer:
    """Wall time spent in the deformers' LSTMs, processors and skinning, per forward.

    Forward hooks on the submodules of every model given to :meth:`attach`; skinning by
    wrapping the ``skin`` the deformer module calls. One timer serves all models: runs
    are sequential, and :meth:`reset` starts a new one.
    """

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)
        self._start: dict[str, float] = {}
        original = deformer_module.skin

        def timed_skin(*args, **kwargs):
            tic = time.perf_counter()
            out = original(*args, **kwargs)
            self.seconds["skinning"] += time.perf_counter() - tic
            return out

        deformer_module.skin = timed_skin

    def attach(self, model: GarmentDeformer) -> None:
        for name in COMPONENTS:
            module = getattr(model, name)
            if module is not None:
                module.register_forward_pre_hook(self._pre(name))
                module.register_forward_hook(self._post(name))

    def _pre(self, name: str) -> Callable:
        def hook(module, inputs) -> None:
            self._start[name] = time.perf_counter()
        return hook

    def _post(self, name: str) -> Callable:
        def hook(module, inputs, output) -> None:
            self.seconds[name] += time.perf_counter() - self._start[name]
        return hook

    def reset(self) -> None:
        self.seconds.clear()


@contextmanager
def bf16_processors(model: GarmentDeformer) -> Iterator[None]:
    """bf16 autocast inside the two M^mp submodules only (everything else float32)."""
    originals = {}
    for name in ("supervised_processor", "physics_processor"):
        module = getattr(model, name)
        if module is None:
            continue
        originals[name] = module.forward

        def forward(*args, _original=module.forward, **kwargs):
            with torch.autocast("cpu", dtype=torch.bfloat16):
                return _original(*args, **kwargs).float()
        module.forward = forward
    try:
        yield
    finally:
        for name, forward in originals.items():
            getattr(model, name).forward = forward


def time_interleaved(runs: dict[str, Callable[[], torch.Tensor]], repeats: int,
                     timer: ComponentTimer) -> dict[str, dict]:
    """Time several variants round-robin (so that they share the machine's load):
    one warm-up each, then ``repeats`` rounds. Per variant: best and median wall time,
    the component times of its best run, its output, and the process's peak RSS right
    after its warm-up (a high-water mark: it includes the variants warmed up before)."""
    outputs, rss = {}, {}
    for name, run in runs.items():
        outputs[name] = run()
        rss[name] = peak_rss_mb()
    times: dict[str, list[float]] = defaultdict(list)
    parts: dict[str, list[dict[str, float]]] = defaultdict(list)
    for _ in range(repeats):
        for name, run in runs.items():
            timer.reset()
            tic = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - tic)
            parts[name].append(dict(timer.seconds))
    result = {}
    for name in runs:
        best = int(np.argmin(times[name]))
        result[name] = {"best_s": times[name][best], "median_s": float(np.median(times[name])),
                        "parts": parts[name][best], "out": outputs[name],
                        "peak_rss_mb": rss[name]}
    return result


def processor_bf16_error(model: GarmentDeformer, pair: GarmentBodyPair, frames: int) -> float:
    """``max |M^mp_bf16(x) − M^mp(x)| / max |M^mp(x)|`` for unit-normal inputs ``x``.

    Freshly initialised, the deformer's own processor inputs are tiny and its blend
    shapes ~1e-8 m, so the posed-vertex error says nothing about bf16 in M^mp; this
    relative error does (multiply by a trained model's blend-shape scale).
    """
    config = model.config
    graph = stack_hierarchies([pair.hierarchy] * frames, config.levels)
    processor = model.supervised_processor
    generator = torch.Generator().manual_seed(0)
    x = torch.randn(frames * pair.rest_pos.shape[0], config.feature_channels * 24,
                    generator=generator)
    reference = processor(x, graph)
    with torch.autocast("cpu", dtype=torch.bfloat16):
        low = processor(x, graph).float()
    return float((low - reference).abs().max() / reference.abs().max())


#: What ``--compile-target`` compiles (``nn.Module.compile``: in place, same weights).
COMPILE_TARGETS = ("model", "processors", "layers")


def compiled_model(base: GarmentDeformer, target: str, mode: str) -> GarmentDeformer:
    """A copy of ``base`` (csr attention, no timing hooks) with ``target`` compiled by
    inductor in ``mode``; compilation happens on the first call of each input shape.

    The per-frame path has graph breaks that no compiler setting removes: the LSTMs
    (dynamo does not trace RNNs), the data-dependent softmax-shift choice
    (``float(aminmax)`` in ``_softmax_shift``), the ``warnings`` filter around each CSR
    tensor, and the ragged skinning's ``repeat_interleave``/``item``; ``model`` compiles
    the pieces in between.
    """
    model = set_attention(copy.deepcopy(base), "csr")
    options = {"backend": "inductor", "mode": None if mode == "default" else mode}
    if target == "model":
        model.compile(**options)
    elif target == "processors":
        for name in ("supervised_processor", "physics_processor"):
            if getattr(model, name) is not None:
                getattr(model, name).compile(**options)
    elif target == "layers":
        from gnngarment.model.graph_attention import GraphAttention

        for name in ("supervised_processor", "physics_processor"):
            module = getattr(model, name)
            for layer in (module.modules() if module is not None else ()):
                if isinstance(layer, GraphAttention):
                    layer.compile(**options)
    else:
        raise ValueError(f"unknown compile target '{target}'")
    return model


class OnnxRuntimeLinear(torch.nn.Module):
    """A bias-free ``nn.Linear`` evaluated by an onnxruntime ``MatMul`` session (as many
    intra-op threads as torch has): the dense projections of M^mp on MLAS instead of
    torch's BLAS, the rest eager."""

    def __init__(self, linear: torch.nn.Linear):
        super().__init__()
        import onnxruntime
        from onnx import TensorProto, helper, numpy_helper

        self.weight = linear.weight  # GraphAttention._scores reads it
        weight = linear.weight.detach().t().contiguous().numpy()
        k, m = weight.shape
        graph = helper.make_graph(
            [helper.make_node("MatMul", ["x", "w"], ["y"])], "linear",
            [helper.make_tensor_value_info("x", TensorProto.FLOAT, ["n", k])],
            [helper.make_tensor_value_info("y", TensorProto.FLOAT, ["n", m])],
            [numpy_helper.from_array(weight, "w")])
        options = onnxruntime.SessionOptions()
        options.intra_op_num_threads = torch.get_num_threads()
        options.inter_op_num_threads = 1
        self.session = onnxruntime.InferenceSession(
            helper.make_model(graph, opset_imports=[helper.make_opsetid("", 18)])
            .SerializeToString(), options, providers=["CPUExecutionProvider"])

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.from_numpy(self.session.run(None, {"x": x.contiguous().numpy()})[0])


def onnxruntime_model(base: GarmentDeformer) -> GarmentDeformer:
    """A copy of ``base`` (csr) whose M^mp GAT projections run on onnxruntime."""
    from gnngarment.model.graph_attention import GraphAttention

    model = set_attention(copy.deepcopy(base), "csr")
    for name in ("supervised_processor", "physics_processor"):
        module = getattr(model, name)
        for layer in (module.modules() if module is not None else ()):
            if isinstance(layer, GraphAttention):
                layer.lin = OnnxRuntimeLinear(layer.lin)
    return model


def allow_recompiles(limit: int = 256) -> None:
    """Raise dynamo's per-function recompile limit (default 8): the GAT code runs at 3
    levels × every batch size, and past the limit dynamo silently falls back to eager."""
    import torch._dynamo

    for name in ("recompile_limit", "cache_size_limit", "accumulated_recompile_limit",
                 "accumulated_cache_size_limit"):
        if hasattr(torch._dynamo.config, name):
            setattr(torch._dynamo.config, name, max(limit, getattr(torch._dynamo.config, name)))


def dynamo_counts() -> tuple[int, int]:
    """(graphs compiled, graph breaks) so far in this process (dynamo's counters)."""
    from torch._dynamo.utils import counters

    return (int(counters["stats"].get("unique_graphs", 0)),
            int(sum(counters["graph_break"].values())))


def onnx_check(model: GarmentDeformer, pair: GarmentBodyPair, frames: int) -> dict:
    """Try both ONNX exporters on the supervised M^mp submodule (``frames`` copies of
    the garment); when ``onnxruntime`` is installed, time its MatMul (as many intra-op
    threads as torch) against torch on M^mp's two largest dense projections
    (the embedding GAT's ``(V, 24 F) @ (24 F, H C)`` and a level-0 GAT's
    ``(V, C) @ (C, H C)``, trained weights, ``V`` = frames × vertices), interleaved,
    median of 8."""
    import io
    import warnings

    result: dict = {"frames": frames, "export": {}}
    config = model.config
    graph = stack_hierarchies([pair.hierarchy] * frames, config.levels)
    processor = model.supervised_processor

    class Processor(torch.nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.processor = processor

        def forward(self, x: torch.Tensor) -> torch.Tensor:
            return self.processor(x, graph)

    x = torch.randn(frames * pair.rest_pos.shape[0], config.feature_channels * 24)
    processor(x, graph)  # builds the cached attention structures, as the first frame does
    for exporter, dynamo in (("torch.export (dynamo=True)", True),
                             ("TorchScript (dynamo=False)", False)):
        tic = time.perf_counter()
        try:
            with warnings.catch_warnings(), torch.no_grad():
                warnings.simplefilter("ignore")
                torch.onnx.export(Processor().eval(), (x,), io.BytesIO(), dynamo=dynamo)
            outcome = "exported"
        except Exception as error:  # any failure: its reason is the result
            cause = error
            while cause.__cause__ is not None:  # the exporter wraps the tracer's error
                cause = cause.__cause__
            outcome = f"failed: {type(cause).__name__}: {str(cause).strip().splitlines()[0][:200]}"
        result["export"][exporter] = {"outcome": outcome, "s": time.perf_counter() - tic}
    try:
        import onnxruntime
        from onnx import TensorProto, helper, numpy_helper
    except ImportError as error:
        result["matmul"] = f"not measured ({error})"
        return result
    options = onnxruntime.SessionOptions()
    options.intra_op_num_threads = torch.get_num_threads()
    options.inter_op_num_threads = 1
    result["onnxruntime"] = onnxruntime.__version__
    result["matmul"] = {}
    rows = frames * pair.rest_pos.shape[0]
    for name, layer in (("embedding", processor.embedding), ("level-0 encoder", None)):
        layer = layer if layer is not None else processor.decoders[0]
        weight = layer.lin.weight.detach().t().contiguous()
        k, m = weight.shape
        onnx_graph = helper.make_graph(
            [helper.make_node("MatMul", ["x", "w"], ["y"])], "matmul",
            [helper.make_tensor_value_info("x", TensorProto.FLOAT, ["n", k])],
            [helper.make_tensor_value_info("y", TensorProto.FLOAT, ["n", m])],
            [numpy_helper.from_array(weight.numpy(), "w")])
        session = onnxruntime.InferenceSession(
            helper.make_model(onnx_graph, opset_imports=[helper.make_opsetid("", 18)])
            .SerializeToString(), options, providers=["CPUExecutionProvider"])
        dense = torch.randn(rows, k)
        feed = {"x": dense.numpy()}
        ours = session.run(None, feed)[0]
        reference = layer.lin(dense)
        times: dict[str, list[float]] = {"torch": [], "onnxruntime": []}
        for _ in range(8):
            tic = time.perf_counter()
            layer.lin(dense)
            times["torch"].append(time.perf_counter() - tic)
            tic = time.perf_counter()
            session.run(None, feed)
            times["onnxruntime"].append(time.perf_counter() - tic)
        result["matmul"][f"{name} ({rows}, {k}) @ ({k}, {m})"] = {
            **{key: float(np.median(value)) for key, value in times.items()},
            "max_rel": float((torch.from_numpy(ours) - reference).abs().max()
                             / reference.abs().max())}
    return result


def initial_model(config: ModelConfig, args: argparse.Namespace
                  ) -> tuple[GarmentDeformer, str]:
    """The trained checkpoint when its network is this config's (realistic activations
    and blend shapes for the bf16 error), else freshly initialised weights (seed 0)."""
    path = Path(args.checkpoint) if args.checkpoint else None
    if path is not None and path.is_file():
        from gnngarment.model.checkpoint import load_model

        model = load_model(path)
        ours, theirs = asdict(model.config), asdict(config)
        # Neither changes the timed network: the attention implementation is swapped
        # below, and the weight prior is one add per skinning weight (the shipped model
        # predates it and keeps ``none``).
        for setting in ("attention", "weight_prior"):
            ours.pop(setting, None)
            theirs.pop(setting, None)
        if ours == theirs:
            return set_attention(model, config.attention).eval(), path.name
    torch.manual_seed(0)
    return GarmentDeformer(config).eval(), "random init"


def start_competitor() -> subprocess.Popen:
    """Another process busy on one core for as long as it runs: a one-thread float32
    GEMM loop, like a second benchmark or a training run beside this one."""
    code = ("import torch; torch.set_num_threads(1); a = torch.randn(512, 512)\n"
            "while True: a = torch.tanh(a @ a)")
    return subprocess.Popen([sys.executable, "-c", code], env=dict(os.environ,
                                                                     OMP_NUM_THREADS="1"))


#: The fused-operator path each ``--attention`` value runs on (``None``: not a
#: GraphAttention choice).
ATTENTION_PATHS = {"csr": "pytorch", "fused": "fused", "pyg": None}


def attention_module(impl: str) -> str:
    """The layer implementation behind an ``--attention`` value (``fused`` is csr's
    GraphAttention on the fused operator)."""
    return "csr" if impl == "fused" else impl


def run_on_path(model: GarmentDeformer, context, inputs: tuple, impl: str) -> torch.Tensor:
    """Posed vertices of one batch, with GraphAttention on ``impl``'s path."""
    with use_attention_path(ATTENTION_PATHS[impl]):
        return model(context, *inputs).posed


def child(args: argparse.Namespace) -> None:
    """Measure one config at one thread count, every implementation in ``--impl``
    interleaved; print one JSON line per implementation."""
    keep_freed_memory()  # applied only in the "kept" children (KEEP_FREED_MEMORY=1)
    if args.threads[0] == "auto":  # what the CLI does: the cores idle right now
        from gnngarment.threads import use_idle_cores

        threads = f"auto={use_idle_cores()}"
    else:
        threads = int(args.threads[0])
        torch.set_num_threads(threads)
    config = load_config(ROOT / "configs" / "model" / f"{args.config}.yaml", ModelConfig)
    pos, faces = flared_skirt(args.vertices)
    pair = make_pair(pos, faces, config)
    base, weights = initial_model(config, args)
    if args.physics[0] == "on":
        base.use_physics = True
    # Else the model's own setting, what `gnngarment animate` runs: a checkpoint records
    # whether its physics submodule is trained and used (the shipped one, a supervised-
    # stage checkpoint, does not use it); freshly initialised weights do not use it.
    physics = "both M^mp" if base.use_physics else "supervised M^mp only"
    timer = ComponentTimer()
    models, contexts, results = {}, {}, {}
    with torch.inference_mode():
        for impl in args.impl:
            models[impl] = set_attention(copy.deepcopy(base), attention_module(impl))
            timer.attach(models[impl])
            tic = time.perf_counter()
            with use_attention_path(ATTENTION_PATHS[impl]):
                contexts[impl] = models[impl].encode([pair])
                path = attention_path()
                reason = fallback_reason()
            results[impl] = {"config": args.config, "attention": impl, "vertices": len(pos),
                             "path": path if ATTENTION_PATHS[impl] else "pyg",
                             "path_reason": reason,
                             "physics": physics,
                             "threads": threads, "weights": weights,
                             "prepare_s": time.perf_counter() - tic,
                             "rss_after_prepare_mb": peak_rss_mb(), "batches": {}}
        compiled: dict[str, GarmentDeformer] = {}
        if args.compile == "on" and "csr" in models:
            allow_recompiles()
            for target in args.compile_target:
                for mode in args.compile_mode:
                    compiled[f"{target}/{mode}"] = compiled_model(base, target, mode)
        if args.onnx and "csr" in models:
            try:
                compiled["onnxruntime MatMul in M^mp"] = onnxruntime_model(base)
            except ImportError as error:
                print(f"onnxruntime variant not measured ({error})", file=sys.stderr)
        for frames in args.batches:
            inputs = frame_inputs(config, frames)
            runs: dict[str, Callable[[], torch.Tensor]] = {
                impl: (lambda m=models[impl], c=contexts[impl], i=inputs, a=impl:
                       run_on_path(m, c, i, a))
                for impl in args.impl}
            first_calls: dict[str, dict] = {}
            if compiled:
                # The batch's graph structures (scipy, numpy) are built by an eager call:
                # traced by dynamo inside the whole forward, that first call fails (torch
                # 2.13: "Guard failed on the same frame it was created" on a from_numpy).
                models["csr"](contexts["csr"], *inputs)
            for name, model in compiled.items():
                # The first call of this shape compiles (or recompiles) and runs once; the
                # csr context is shared (same weights, same cached graph structures).
                graphs, breaks = dynamo_counts()
                tic = time.perf_counter()
                model(contexts["csr"], *inputs)
                after = dynamo_counts()
                first_calls[name] = {"first_call_s": time.perf_counter() - tic,
                                     "graphs": after[0] - graphs, "breaks": after[1] - breaks}
                runs["compiled " + name] = (
                    lambda m=model, c=contexts["csr"], i=inputs: m(c, *i).posed)
            if args.bf16 and "csr" in models:
                model, context = models["csr"], contexts["csr"]

                def whole(m=model, c=context, i=inputs) -> torch.Tensor:
                    with torch.autocast("cpu", dtype=torch.bfloat16):
                        return m(c, *i).posed.float()

                def processors(m=model, c=context, i=inputs) -> torch.Tensor:
                    with bf16_processors(m):
                        return m(c, *i).posed

                runs["bf16"], runs["bf16_processors"] = whole, processors
            timed = time_interleaved(runs, args.repeats, timer)
            for impl in args.impl:
                entry = {k: v for k, v in timed[impl].items() if k != "out"}
                if impl != args.impl[0]:
                    entry["max_diff_vs_" + args.impl[0]] = float(
                        (timed[impl]["out"] - timed[args.impl[0]]["out"]).abs().max())
                results[impl]["batches"][str(frames)] = entry
            if compiled:
                results["csr"]["batches"][str(frames)]["compiled"] = {
                    name: {**first_calls[name],
                           "best_s": timed["compiled " + name]["best_s"],
                           "median_s": timed["compiled " + name]["median_s"],
                           "max_diff_m": float((timed["compiled " + name]["out"]
                                                - timed["csr"]["out"]).abs().max())}
                    for name in compiled}
            for mode in ("bf16", "bf16_processors"):
                if mode in timed:
                    error = (timed[mode]["out"] - timed["csr"]["out"]).abs() * 1000  # mm
                    results["csr"]["batches"][str(frames)][mode] = {
                        "best_s": timed[mode]["best_s"], "max_mm": float(error.max()),
                        "mean_mm": float(error.mean()),
                        "processor_rel": processor_bf16_error(models["csr"], pair, frames)}
        if args.profile_batch in args.batches and "csr" in models:
            from torch.profiler import ProfilerActivity, profile
            inputs = frame_inputs(config, args.profile_batch)
            with profile(activities=[ProfilerActivity.CPU]) as prof:
                models["csr"](contexts["csr"], *inputs)
            results["csr"]["profile"] = prof.key_averages().table(
                sort_by="self_cpu_time_total", row_limit=12)
    if args.onnx and "csr" in models:  # outside inference_mode: the exporters trace
        with torch.no_grad():
            results["csr"]["onnx"] = onnx_check(models["csr"], pair, max(args.batches))
    for result in results.values():
        print("RESULT " + json.dumps(result))


def measure_simulator(pos: np.ndarray, faces: np.ndarray, frames: int) -> float | None:
    """Newton simulator frames/s on the skirt (waist pinned) around a capsule body
    (~5k triangles) that sways and bobs; ``None`` with a printed reason if it cannot run.
    """
    # ------------------------------------------------------------------------------
    # SIMULATOR MEASUREMENT (model fps ÷ simulator fps is the ratio the docs report)
    # ------------------------------------------------------------------------------
    try:
        import trimesh

        from data_prep.simulate import SimulationFailed, SimulationSettings, simulate_garment
    except ImportError as error:
        print(f"simulator: not measured ({error})")
        return None
    try:
        import warp

        warp.config.quiet = True  # keep Warp's banner and per-module lines out of the report
    except ImportError:
        pass
    fps = 30.0
    body = trimesh.creation.capsule(height=0.9, radius=0.1, count=[50, 50])
    rest = np.asarray(body.vertices) + np.array([0.0, 0.0, -0.25])   # z in [-0.8, 0.3]
    t = np.arange(frames) / fps
    offset = np.stack([0.04 * np.sin(2 * np.pi * t), np.zeros_like(t),
                       0.01 * np.sin(4 * np.pi * t)], axis=1)         # (T, 3) metres
    body_vertices = rest[None] + offset[:, None]
    ring = np.flatnonzero(pos[:, 2] > -1e-9)
    pin_targets = pos[ring][None] + offset[:, None]
    settings = SimulationSettings(max_retries=0)
    tic = time.perf_counter()
    try:
        result = simulate_garment(pos, faces, body_vertices, np.asarray(body.faces), fps,
                                  "cotton", pinned=ring, pin_targets=pin_targets,
                                  settings=settings)
    except SimulationFailed as error:
        print(f"simulator: not measured (failed its quality gates: {error})")
        return None
    print(f"simulator: {len(pos)} vertices, capsule of {len(body.faces)} triangles, "
          f"{frames} frames + {settings.settle_frames} settle, {result.substeps} substeps × "
          f"{settings.iterations} iterations, one core: {result.seconds_per_frame:.3f} "
          f"s/frame = {1 / result.seconds_per_frame:.2f} frames/s (wall "
          f"{time.perf_counter() - tic:.0f} s incl. setup)")
    return 1 / result.seconds_per_frame


def variant(r: dict) -> str:
    """The network timed: config and which M^mp submodules ran."""
    return f"{r['config']} ({r['physics']})"


def label(r: dict) -> str:
    attention = r["attention"] + (f" (child: {r['child']})" if "child" in r else "")
    return f"{variant(r)} | {attention} | {r.get('malloc', 'default')} | {r['threads']}"


def report(results: list[dict]) -> dict[str, float]:
    """Print the tables; return each config's (and physics setting's) best float32
    frames/s at the largest batch."""
    best: dict[str, float] = {}
    print("\n## frames/s (best of repeats; float32, inference_mode)")
    print("| config | attention | malloc | threads | batch | ms/batch | frames/s "
          "| median frames/s | peak RSS MB |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in results:
        largest = max(int(b) for b in r["batches"])
        for frames, e in r["batches"].items():
            fps = int(frames) / e["best_s"]
            if int(frames) == largest:
                best[variant(r)] = max(best.get(variant(r), 0.0), fps)
                key = f"{variant(r)}, {r['attention']}"
                best[key] = max(best.get(key, 0.0), fps)
            print(f"| {label(r)} | {frames} | {1000 * e['best_s']:.0f} | {fps:.1f} "
                  f"| {int(frames) / e['median_s']:.1f} | {e['peak_rss_mb']:.0f} |")
    for r in results:
        for frames, e in r["batches"].items():
            for key, diff in e.items():
                if key.startswith("max_diff_vs_"):
                    print(f"max |posed({r['attention']}) − posed({key[12:]})|, {label(r)}, "
                          f"batch {frames}: {diff:.2e} m")

    pairs = [(r, q) for r in results for q in results
             if r["attention"] == "fused" and q["attention"] == "csr"
             and label(r).split("|", 2)[2] == label(q).split("|", 2)[2]
             and variant(r) == variant(q)]
    if pairs:
        print("\n## fused operator vs its PyTorch fallback (same child, interleaved)")
        print("| config | malloc | threads | batch | path | fallback frames/s "
              "| fused frames/s | fused ÷ fallback (best) | (median) |")
        print("|---|---|---|---|---|---|---|---|---|")
        for r, q in pairs:
            for frames, e in r["batches"].items():
                o = q["batches"][frames]
                path = r["path"] + (f" ({r['path_reason']})" if r.get("path_reason") else "")
                print(f"| {variant(r)} | {r.get('malloc', 'default')} | {r['threads']} "
                      f"| {frames} | {path} | {int(frames) / o['best_s']:.1f} "
                      f"| {int(frames) / e['best_s']:.1f} | {o['best_s'] / e['best_s']:.2f}× "
                      f"| {o['median_s'] / e['median_s']:.2f}× |")

    print("\n## where the time goes (best run, ms per batch)")
    print("| config | attention | malloc | threads | batch | E^t1 LSTM | E^t2 LSTM "
          "| M^mp sup. | M^mp phys. | skinning | rest | total |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        for frames, e in r["batches"].items():
            p = {k: 1000 * v for k, v in e["parts"].items()}
            total = 1000 * e["best_s"]
            print(f"| {label(r)} | {frames} "
                  f"| {p.get('pose_encoder', 0):.0f} | {p.get('velocity_encoder', 0):.0f} "
                  f"| {p.get('supervised_processor', 0):.0f} "
                  f"| {p.get('physics_processor', 0):.0f} | {p.get('skinning', 0):.0f} "
                  f"| {total - sum(p.values()):.0f} | {total:.0f} |")

    if any("bf16" in e for r in results for e in r["batches"].values()):
        print("\n## bf16 autocast vs float32")
        print("posed-vertex error vs float32 (with random-init weights the blend shapes are "
              "~1e-8 m: only the skinning-weight path shows); M^mp relative error on "
              "unit-normal inputs. Weights: " + ", ".join(sorted(
                  {f"{r['config']}: {r['weights']}" for r in results})))
        print("| config | attention | malloc | threads | batch | bf16 where | frames/s "
              "| speed-up | max err mm | mean err mm | M^mp rel. err |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
        for r in results:
            for frames, e in r["batches"].items():
                for mode, where in (("bf16", "whole forward"),
                                    ("bf16_processors", "M^mp only")):
                    if mode not in e:
                        continue
                    m = e[mode]
                    print(f"| {label(r)} | {frames} | {where} "
                          f"| {int(frames) / m['best_s']:.1f} "
                          f"| {e['best_s'] / m['best_s']:.2f}× | {m['max_mm']:.3f} "
                          f"| {m['mean_mm']:.4f} | {m['processor_rel']:.1e} |")
    if any("compiled" in e for r in results for e in r["batches"].values()):
        print("\n## compiled variants (torch.compile, inductor CPU; onnxruntime MatMul) vs "
              "eager, csr, float32")
        print("Interleaved with the eager runs of the same process. first call: compile + "
              "one run at this batch size (a recompile for the second size); graphs / "
              "breaks: what dynamo compiled at that call; ratio: eager time ÷ compiled "
              "time (> 1: compiled faster); Δ: max |posed(compiled) − posed(eager)|.")
        print("| config | malloc | threads | batch | compiled | first call s | graphs "
              "| breaks | eager frames/s | compiled frames/s | ratio (best) "
              "| ratio (median) | Δ m |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in results:
            for frames, e in r["batches"].items():
                for name, c in e.get("compiled", {}).items():
                    print(f"| {r['config']} | {r.get('malloc', 'default')} | {r['threads']} "
                          f"| {frames} | {name} | {c['first_call_s']:.1f} | {c['graphs']} "
                          f"| {c['breaks']} | {int(frames) / e['best_s']:.1f} "
                          f"| {int(frames) / c['best_s']:.1f} | {e['best_s'] / c['best_s']:.2f} "
                          f"| {e['median_s'] / c['median_s']:.2f} | {c['max_diff_m']:.1e} |")
    for r in results:
        if "onnx" not in r:
            continue
        o = r["onnx"]
        print(f"\n## ONNX, {label(r)}: supervised M^mp submodule, {o['frames']} frames")
        for exporter, outcome in o["export"].items():
            print(f"{exporter}: {outcome['outcome']} ({outcome['s']:.1f} s)")
        if isinstance(o["matmul"], str):
            print(f"onnxruntime MatMul: {o['matmul']}")
        else:
            print(f"onnxruntime {o['onnxruntime']} MatMul vs torch ({r['threads']} threads, "
                  "median of 8, interleaved):")
            print("| projection | torch ms | onnxruntime ms | torch ÷ ORT | max rel. diff |")
            print("|---|---|---|---|---|")
            for name, m in o["matmul"].items():
                print(f"| {name} | {1000 * m['torch']:.1f} | {1000 * m['onnxruntime']:.1f} "
                      f"| {m['torch'] / m['onnxruntime']:.2f} | {m['max_rel']:.1e} |")
    for r in results:
        print(f"\n{label(r)}: prepare (per pair, once) {r['prepare_s']:.2f} s; peak RSS "
              f"after prepare {r['rss_after_prepare_mb']:.0f} MB")
        if "profile" in r:
            print(f"top operators, batch {max(int(b) for b in r['batches'])}:\n{r['profile']}")
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--vertices", type=int, default=5000)
    parser.add_argument("--configs", nargs="+", default=["small", "paper"])
    parser.add_argument("--batches", type=int, nargs="+", default=[1, 16])
    parser.add_argument("--attention", nargs="+", default=["csr", "pyg"],
                        choices=["csr", "fused", "pyg"],
                        help="csr: GraphAttention's PyTorch path (the fallback); fused: "
                             "GraphAttention on the fused C++ operator; pyg: GATConv")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--threads", nargs="+", default=["1", "2", "auto"],
                        choices=["1", "2", "3", "4", "8", "16", "auto"],
                        help="intra-op threads (each value measured separately); auto: "
                             "the idle cores at start, as the CLI chooses them")
    parser.add_argument("--checkpoint", default=str(ROOT / "models" / "gnngarment-small.pt"),
                        help="trained weights, used for the config whose network they fit "
                             "('' for random init everywhere)")
    parser.add_argument("--no-bf16", dest="bf16", action="store_false")
    parser.add_argument("--no-simulator", dest="simulator", action="store_false")
    parser.add_argument("--sim-frames", type=int, default=30)
    parser.add_argument("--malloc", nargs="+", choices=["default", "kept", "tuned"],
                        default=["default", "kept"],
                        help="glibc malloc settings of the csr runs (pyg: the first): "
                             "default: glibc's; kept: gnngarment.allocator."
                             "keep_freed_memory(), what every gnngarment command sets; "
                             "tuned: the MALLOC_*_THRESHOLD_ environment variables")
    parser.add_argument("--compete", action="store_true",
                        help="run a competing process (a one-thread float32 GEMM loop) "
                             "on the machine during every measurement")
    parser.add_argument("--profile-batch", type=int, default=16,
                        help="print the top operators of the csr runs at this batch")
    parser.add_argument("--compile", choices=["off", "on"], default="off",
                        help="on: also time torch.compile'd copies of the csr model, "
                             "interleaved with eager csr (always timed: the reference)")
    parser.add_argument("--compile-target", nargs="+", default=["model"],
                        choices=COMPILE_TARGETS,
                        help="what --compile on compiles (each value a variant)")
    parser.add_argument("--compile-mode", nargs="+", default=["default"],
                        choices=["default", "max-autotune-no-cudagraphs"],
                        help="torch.compile mode (each value a variant)")
    parser.add_argument("--compile-cache", choices=["cold", "warm"], default="cold",
                        help="cold: each compiled child starts with an empty inductor "
                             "cache (the first call is the full compile); warm: the "
                             "default cache, as a second run on the same machine")
    parser.add_argument("--physics", nargs="+", choices=["checkpoint", "on"],
                        default=["checkpoint", "on"],
                        help="checkpoint: the model's own use_physics, as `gnngarment "
                             "animate` runs it (the shipped supervised-stage checkpoint: "
                             "the supervised M^mp only); on: both M^mp submodules, as a "
                             "model trained through the physics stage runs")
    parser.add_argument("--onnx", action="store_true",
                        help="try exporting M^mp to ONNX; time onnxruntime's MatMul, alone "
                             "and inside M^mp (needs onnxruntime and onnx)")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--config", help=argparse.SUPPRESS)
    parser.add_argument("--impl", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args)
        return

    print(f"torch {torch.__version__}, threads {args.threads}, {args.vertices}-vertex skirt, "
          f"best of {args.repeats}; load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores")
    results = []
    variants = list(dict.fromkeys(args.malloc))
    competitor = start_competitor() if args.compete else None
    # Compiled variants: one child each (with its own eager csr reference, interleaved),
    # since dynamo's caches live on the code objects that all variants share: in one
    # process a second variant would reuse the first one's graphs and its first call
    # would not show its compile time.
    extras: list[tuple[str, list[str]]] = []
    if args.compile == "on":
        extras += [(f"compile {target}/{mode}",
                    ["--compile", "on", "--compile-target", target, "--compile-mode", mode])
                   for target in args.compile_target for mode in args.compile_mode]
    if args.onnx:
        extras.append(("onnx", ["--onnx"]))
    jobs = []
    for threads, config, physics in ((t, c, p) for t in args.threads for c in args.configs
                                     for p in dict.fromkeys(args.physics)):
        for malloc in variants:
            # All implementations in one child, interleaved; the tuned-malloc child only
            # repeats the csr runs (the environment must be set when the process starts).
            impls = args.attention if malloc == variants[0] else ["csr"]
            # Without pyg, bf16 or a profile, the extras' children measure all of it.
            redundant = (extras and impls == ["csr"] and not args.bf16
                         and args.profile_batch not in args.batches)
            if not redundant:
                jobs.append((threads, config, physics, malloc, impls, None, []))
            if malloc == variants[0]:
                jobs += [(threads, config, physics, malloc, ["csr"], name, extra)
                         for name, extra in extras]
    for threads, config, physics, malloc, impls, extra_name, extra in jobs:
        main_child = extra_name is None
        command = [sys.executable, __file__, "--child", "--config", config,
                   "--checkpoint", args.checkpoint, "--physics", physics,
                   "--impl", *impls, "--vertices", str(args.vertices),
                   "--repeats", str(args.repeats), "--threads", str(threads),
                   "--profile-batch",
                   str(args.profile_batch if main_child and malloc == variants[0] else -1),
                   "--batches", *map(str, args.batches), *extra]
        if not args.bf16 or malloc != variants[0] or not main_child:
            command.append("--no-bf16")
        env = dict(os.environ, **(MALLOC_TUNED if malloc == "tuned" else {}))
        env[KEEP_FREED_MEMORY] = "1" if malloc == "kept" else "0"
        if threads == "auto":  # the choice is the child's, not a variable's
            env.pop("OMP_NUM_THREADS", None)
        cache = None
        if extra_name is not None and extra_name.startswith("compile") \
                and args.compile_cache == "cold":
            # An empty inductor cache: the first call shows the whole compile time, as
            # on a fresh machine (warm: whatever earlier runs left in the default cache).
            cache = tempfile.TemporaryDirectory(prefix="inductor-cache-")
            env["TORCHINDUCTOR_CACHE_DIR"] = cache.name
        tic = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
        if cache is not None:
            cache.cleanup()
        lines = [ln for ln in done.stdout.splitlines() if ln.startswith("RESULT ")]
        what = (f"{config}/{physics}/{malloc}/{threads} threads"
                + (f" ({extra_name})" if extra else ""))
        if done.returncode != 0 or not lines:
            print(f"{what} failed:\n{done.stderr[-3000:]}")
            continue
        for line in lines:
            result = json.loads(line[len("RESULT "):])
            result["malloc"] = malloc
            if extra_name is not None:
                result["child"] = extra_name
            results.append(result)
        print(f"measured {config} ({', '.join(impls)}), physics {physics}, malloc {malloc}, "
              f"{threads} threads"
              f"{f', {extra_name}' if extra_name else ''}, in {time.perf_counter() - tic:.0f} s",
              flush=True)
    best = report(results)
    if competitor is not None:
        competitor.kill()
        competitor.wait()
        print("(a competing one-thread GEMM process ran during every measurement above)")

    print()
    simulator_fps = None
    if args.simulator:
        pos, faces = flared_skirt(args.vertices)
        simulator_fps = measure_simulator(pos, faces, args.sim_frames)
    else:
        print("simulator: not measured (--no-simulator)")
    for config, fps in best.items():
        if simulator_fps:
            print(f"model ÷ simulator, {config}: {fps:.1f} / {simulator_fps:.2f} frames/s = "
                  f"{fps / simulator_fps:.0f}× (fastest float32 variant, batch "
                  f"{max(args.batches)})")
        else:
            print(f"model ÷ simulator, {config}: simulator not measured")

if __name__ == "__main__":
    main()
