"""The fused CPU graph-attention operator: loader, autograd function and path choice.

:class:`~gnngarment.model.graph_attention.GraphAttention` computes, per head, LeakyReLU
logits on the edges, their softmax over every node's incoming edges and the weighted sum
of the neighbours' projected features. In PyTorch that is several passes over
``(E'·H,)`` tensors (gather, exp, segment sum, divide) and a CSR × dense product. The
C++ operator in ``csrc/graph_attention.cpp`` (``torch.ops.gnngarment.*``, registered
with ``TORCH_LIBRARY``) does it in one pass over each CSR row, parallel over rows, and
its backward recomputes the softmax from the saved per-row maxima and sums (nothing per
edge is kept from the forward; inside the backward, the row pass hands each edge's
softmax weight and logit gradient to the column pass, 2 values per edge and head, so the
per-edge dot product is computed once). The PyTorch path stays as the fallback and the
reference.

**How it is built**: compiled on first use (the first GAT forward, or
:func:`attention_path`) by the C++ compiler found on ``PATH`` (``$CXX``, ``c++``,
``g++``) against the installed torch, into a per-user cache
(``$GNNGARMENT_EXTENSION_DIR``, default ``~/.cache/gnngarment/extensions``), keyed by a
hash of the source, the flags, torch's version and the CPU (it is built with
``-march=native``); later processes load the cached library (~10 s for the first build,
then milliseconds). Not at ``pip install`` time: setuptools builds in an isolated
environment without torch (the Makefile installs the CPU wheel first, on its own,
precisely so that nothing pulls another torch), so a build step there would need
``--no-build-isolation`` everywhere the package is installed, and a wheel built on one
CPU would carry ``-march=native`` code to another. The compiler is called directly (no
ninja, which ``torch.utils.cpp_extension.load`` requires and a fresh machine may lack).
Any failure (no compiler, a compile error, a library that does not load) leaves the
PyTorch path in use, and :func:`attention_path` says why.

``GNNGARMENT_ATTENTION`` (read at each call, not at import) picks the path: ``pytorch``
always the reference; ``fused`` the operator wherever it is available; ``auto`` (the
default) the operator for inference, and where autograd records the forward the path
:data:`AUTO_UNDER_AUTOGRAD` names (the one measured faster in training).
:func:`use_attention_path` does the same for a block of code.

Shapes follow :class:`~gnngarment.model.graph_attention.GraphAttention`.
"""

from __future__ import annotations

import hashlib
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import threading
import weakref
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import torch
from torch.autograd.function import once_differentiable

from gnngarment.model.attention_graph import AttentionGraph
from gnngarment.model.sparse_matrix import structure_mode

#: The operator's source, next to this file (shipped as package data).
SOURCE = Path(__file__).resolve().parent / "csrc" / "graph_attention.cpp"
#: Environment variable that picks the path: ``pytorch``, ``fused`` or ``auto``.
PATH_VARIABLE = "GNNGARMENT_ATTENTION"
#: Environment variable naming the folder of compiled operators.
CACHE_VARIABLE = "GNNGARMENT_EXTENSION_DIR"
#: The two paths.
PATHS = ("fused", "pytorch")
#: Flags tried in turn: the CPU's own instructions first, portable code if the compiler
#: does not know ``-march=native``.
_ARCH_FLAGS = (["-march=native"], [])
#: What ``auto`` uses where autograd records the forward (training): on the shipped
#: training recipe the fused path measured 1.09x (supervised), 1.14x (physics) and 1.17x
#: (physics + strain) the PyTorch path's frames/s, mean of six rounds on 2 AMD EPYC cores
#: (docs/performance.md, "Current figures"; docs/experiments/2026-12-06-speed-fused-attention.md).
AUTO_UNDER_AUTOGRAD = "fused"
#: Seconds a compile may take before it counts as failed.
_COMPILE_TIMEOUT = 600

_lock = threading.Lock()
_state: dict[str, str | None] = {}          # "path", "reason", "library" once loaded
_override: list[str] = []                   # innermost use_attention_path() last
#: Transposed index arrays per graph (the backward's column pass), built once.
_transposes: weakref.WeakKeyDictionary[AttentionGraph, tuple[torch.Tensor, torch.Tensor]] = \
    weakref.WeakKeyDictionary()


def attention_path(grad: bool = False) -> str:
    """``"fused"`` when GAT layers use the fused operator, else ``"pytorch"``
    (:func:`fallback_reason` says why), for inference (``grad=False``) or for a forward
    that autograd records (``grad=True``: training). Builds or loads the operator on
    first call."""
    return "pytorch" if fallback_reason(grad) else "fused"


def fallback_reason(grad: bool = False) -> str | None:
    """Why the PyTorch path is used (``None`` when the fused one is); ``grad`` as in
    :func:`attention_path`."""
    requested = _requested()
    if requested == "pytorch":
        source = "use_attention_path('pytorch')" if _override else f"{PATH_VARIABLE}=pytorch"
        return f"forced by {source}"
    if not _load():
        return _state.get("reason")
    if requested == "auto" and grad and AUTO_UNDER_AUTOGRAD == "pytorch":
        return (f"the default under autograd (measured slower than the PyTorch path; "
                f"{PATH_VARIABLE}=fused uses it)")
    return None


@contextmanager
def use_attention_path(path: str | None) -> Iterator[None]:
    """Inside the block, GAT layers use ``path`` (``"fused"``: when available,
    ``"pytorch"``: always the reference); ``None`` changes nothing. Not thread-local:
    for benchmarks and tests."""
    if path is None:
        yield
        return
    if path not in PATHS:
        raise ValueError(f"attention path must be one of {PATHS}, got '{path}'")
    _override.append(path)
    try:
        yield
    finally:
        _override.pop()


def fused_applicable(h: torch.Tensor, training_dropout: bool, grad: bool) -> bool:
    """Whether a layer with projected features ``h`` runs on the fused operator: CPU,
    float32/float64, no attention dropout (the operator has none), and the path chosen
    (:func:`attention_path`) for a forward with (``grad``) or without autograd."""
    return (not training_dropout and h.device.type == "cpu"
            and h.dtype in (torch.float32, torch.float64) and attention_path(grad) == "fused")


def fused_graph_attention(h: torch.Tensor, a_src: torch.Tensor, a_dst: torch.Tensor,
                          bias: torch.Tensor, graph: AttentionGraph, negative_slope: float,
                          concat: bool) -> torch.Tensor:
    """GAT aggregation by the fused operator (differentiable w.r.t. ``h``, ``a_src``,
    ``a_dst`` and ``bias``).

    Shapes:
        h ``(N, H·C)``, a_src and a_dst ``(N, H)`` (rows may be strided: columns of the
        layer's score matrix), bias ``(H·C,)`` or ``(C,)`` → ``(N, H·C)`` if ``concat``
        else ``(N, C)``.
    """
    h = h.contiguous()
    if torch.is_grad_enabled() and any(t.requires_grad for t in (h, a_src, a_dst, bias)):
        return _FusedGraphAttention.apply(h, a_src, a_dst, bias, graph, negative_slope,
                                          concat)
    return _forward(h, a_src, a_dst, bias, graph, negative_slope, concat)[0]


def _blocks(graph: AttentionGraph) -> list[tuple[AttentionGraph, int]]:
    """The graph as runs of identical copies (one run of itself if not known)."""
    return list(graph.blocks) if graph.blocks is not None else [(graph, 1)]


def _forward(h: torch.Tensor, a_src: torch.Tensor, a_dst: torch.Tensor, bias: torch.Tensor,
             graph: AttentionGraph, negative_slope: float, concat: bool
             ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """``(out, row_max, row_sum)``: one operator call over every block (each copy reads
    its block's one set of index arrays; the blocks write into one output)."""
    blocks = _blocks(graph)
    return torch.ops.gnngarment.graph_attention_forward(
        [block.ptr for block, _ in blocks], [block.source for block, _ in blocks],
        [copies for _, copies in blocks], h, a_src, a_dst, bias.detach(), negative_slope,
        concat)


def _transpose(graph: AttentionGraph) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """``(ptr_t, target, edge_t)``: the edges out of node ``j`` go to
    ``target[ptr_t[j]:ptr_t[j+1]]`` and are edges ``edge_t[ptr_t[j]:ptr_t[j+1]]`` of the
    graph's CSR order (repeated edges kept; a stable sort, so the order is deterministic)."""
    cached = _transposes.get(graph)
    if cached is None:
        with structure_mode():
            n = graph.num_nodes
            degree = graph.ptr[1:] - graph.ptr[:-1]
            target = torch.repeat_interleave(torch.arange(n), degree)
            order = torch.argsort(graph.source, stable=True)
            counts = torch.bincount(graph.source, minlength=n)
            ptr_t = torch.cat([counts.new_zeros(1), torch.cumsum(counts, 0)])
            cached = (ptr_t, target[order].contiguous(), order.contiguous())
        _transposes[graph] = cached
    return cached


class _FusedGraphAttention(torch.autograd.Function):
    """The fused operator with its fused backward (first order only)."""

    @staticmethod
    def forward(ctx, h: torch.Tensor, a_src: torch.Tensor,  # type: ignore[override]
                a_dst: torch.Tensor, bias: torch.Tensor, graph: AttentionGraph,
                negative_slope: float, concat: bool) -> torch.Tensor:
        out, row_max, row_sum = _forward(h, a_src, a_dst, bias, graph, negative_slope, concat)
        ctx.save_for_backward(h, a_src, a_dst, row_max, row_sum)
        ctx.graph, ctx.negative_slope, ctx.concat = graph, negative_slope, concat
        return out

    @staticmethod
    @once_differentiable
    def backward(ctx, grad: torch.Tensor):  # type: ignore[override]
        h, a_src, a_dst, row_max, row_sum = ctx.saved_tensors
        grad = grad.contiguous()
        blocks = _blocks(ctx.graph)
        transposes = [_transpose(block) for block, _ in blocks]
        grad_h, grad_src, grad_dst = torch.ops.gnngarment.graph_attention_backward(
            [block.ptr for block, _ in blocks], [block.source for block, _ in blocks],
            [t[0] for t in transposes], [t[1] for t in transposes],
            [t[2] for t in transposes], [copies for _, copies in blocks], grad, h, a_src,
            a_dst, row_max, row_sum, ctx.negative_slope, ctx.concat)
        grad_bias = grad.sum(0) if ctx.needs_input_grad[3] else None
        return grad_h, grad_src, grad_dst, grad_bias, None, None, None


def _requested() -> str:
    """``pytorch``, ``fused`` or ``auto`` (also for an unknown value of the variable)."""
    if _override:
        return _override[-1]
    value = os.environ.get(PATH_VARIABLE, "auto").strip().lower()
    return value if value in PATHS else "auto"


def _load() -> bool:
    """Load (building first if needed) the operator once per process; ``False`` with
    ``_state["reason"]`` set when it is unavailable."""
    if "path" in _state:
        return _state["path"] == "fused"
    with _lock:
        if "path" not in _state:
            try:
                library = _build()
                torch.ops.load_library(str(library))
                _register_fake()
                _state.update(path="fused", reason=None, library=str(library))
            except Exception as error:  # any failure: the PyTorch path, with the reason
                _state.update(path="pytorch", reason=f"{type(error).__name__}: {error}")
    return _state["path"] == "fused"


def loaded_library() -> str | None:
    """Path of the loaded operator library (``None`` if not loaded)."""
    _load()
    return _state.get("library")


def _compiler() -> str:
    for candidate in (os.environ.get("CXX"), "c++", "g++", "clang++"):
        if candidate and shutil.which(candidate):
            return candidate
    raise RuntimeError("no C++ compiler found ($CXX, c++, g++, clang++)")


def _cache_dir() -> Path:
    if os.environ.get(CACHE_VARIABLE):
        return Path(os.environ[CACHE_VARIABLE])
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "gnngarment" / "extensions"


def _cpu_signature() -> str:
    """What ``-march=native`` depends on: the CPU model and its instruction flags."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        return platform.processor() or platform.machine()
    wanted = [line for line in lines if line.startswith(("model name", "flags"))]
    return "\n".join(dict.fromkeys(wanted))


def _command(compiler: str, arch: list[str], output: Path) -> list[str]:
    from torch.utils.cpp_extension import include_paths, library_paths

    torch_lib = library_paths()[0]
    abi = int(torch._C._GLIBCXX_USE_CXX11_ABI)
    return [compiler, "-O3", *arch, "-fopenmp", "-shared", "-fPIC", "-std=c++20",
            f"-D_GLIBCXX_USE_CXX11_ABI={abi}",
            *(f"-I{path}" for path in include_paths()), str(SOURCE), "-o", str(output),
            f"-L{torch_lib}", "-lc10", "-ltorch_cpu", f"-Wl,-rpath,{torch_lib}"]


def _build() -> Path:
    """The compiled library in the cache (compiled now if absent). Concurrent processes
    (test workers) serialise on a lock file; the library appears by an atomic rename."""
    if sys.platform != "linux":
        raise RuntimeError(f"the fused operator is built on Linux only ({sys.platform})")
    compiler = _compiler()
    folder = _cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    errors = []
    for arch in _ARCH_FLAGS:
        key = hashlib.sha256("\0".join([
            SOURCE.read_text(), torch.__version__, " ".join(_command(compiler, arch, Path())),
            _cpu_signature() if arch else "", platform.python_version()]).encode()).hexdigest()
        library = folder / f"graph_attention-{key[:16]}.so"
        with _file_lock(folder / f"{library.name}.lock"):
            if library.is_file():
                return library
            with tempfile.TemporaryDirectory(dir=folder) as scratch:
                temporary = Path(scratch) / library.name
                done = subprocess.run(_command(compiler, arch, temporary), capture_output=True,
                                      text=True, timeout=_COMPILE_TIMEOUT, check=False)
                if done.returncode == 0:
                    os.replace(temporary, library)
                    return library
                errors.append(done.stderr.strip()[-2000:])
    raise RuntimeError(f"{compiler} failed to build {SOURCE.name}:\n" + "\n".join(errors))


@contextmanager
def _file_lock(path: Path) -> Iterator[None]:
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock, the rename keeps readers safe
        yield
        return
    with open(path, "w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _register_fake() -> None:
    """Shape functions of both operators (for torch.compile / fake tensors)."""
    if getattr(_register_fake, "done", False):
        return

    @torch.library.register_fake("gnngarment::graph_attention_forward")
    def _forward_fake(ptr, source, copies, h, a_src, a_dst, bias, negative_slope, concat):
        heads = a_src.shape[1]
        width = h.shape[1] if concat else h.shape[1] // heads
        return (h.new_empty(h.shape[0], width), a_src.new_empty(a_src.shape),
                a_src.new_empty(a_src.shape))

    @torch.library.register_fake("gnngarment::graph_attention_backward")
    def _backward_fake(ptr, source, ptr_t, target, edge_t, copies, grad, h, a_src, a_dst,
                       row_max, row_sum, negative_slope, concat):
        return h.new_empty(h.shape), a_src.new_empty(a_src.shape), a_src.new_empty(a_src.shape)

    _register_fake.done = True  # type: ignore[attr-defined]
