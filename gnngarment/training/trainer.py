"""The training loop: two stages, progress, TensorBoard, atomic checkpoints, exact resume,
optional data parallelism (torchrun + DDP, gloo on CPU)."""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from gnngarment.data.dataset import PreparedDataset, TrainingBatch
from gnngarment.io.atomic import atomic_write_bytes
from gnngarment.model.checkpoint import load_checkpoint, model_payload, save_checkpoint
from gnngarment.model.config import ModelConfig
from gnngarment.model.deformer import DeformerOutput, GarmentDeformer, check_pair_fits
from gnngarment.training.config import TrainingConfig
from gnngarment.training.objective import stage_loss
from gnngarment.training.rng import rng_state, set_rng_state
from gnngarment.training.stage_schedule import StageSchedule

CHECKPOINT_NAME = "last.pt"
SUPERVISED_CHECKPOINT_NAME = "supervised.pt"
METRICS_NAME = "metrics.jsonl"


class RunFolderError(ValueError):
    """A new run was started into a folder that holds another run's checkpoint (the
    message names it and says how to continue or start over)."""


class TrainingStep(nn.Module):
    """``encode`` + ``forward`` as one module call, so DDP sees the whole computation
    (its gradient hooks cover the per-pair encoders too)."""

    def __init__(self, model: GarmentDeformer):
        super().__init__()
        self.model = model

    def forward(self, batch: TrainingBatch) -> DeformerOutput:
        context = self.model.encode(batch.pairs)
        offsets = None
        if self.model.has_dynamics:
            assert batch.sequence_transforms is not None
            offsets = self.model.dynamic_blend_shapes(
                context, batch.sequence_transforms, torch.as_tensor(batch.frames), batch.fps)
        return self.model(context, batch.motion_windows, batch.velocity_windows,
                          batch.joint_transforms, offsets)


def _check_cache_fits(dataset: PreparedDataset, model: ModelConfig) -> None:
    """Refuse a cache prepared for another model config before the first epoch, naming
    the cache and the setting (a mismatch would otherwise surface mid-epoch)."""
    name = dataset.sequence_names[0]
    try:
        check_pair_fits(dataset.garment_of(name).pair, model)
    except ValueError as error:
        raise ValueError(f"{dataset.root}: {name}: {error}: the cache was prepared for "
                         "another model config (rebuild it, or change the model config)"
                         ) from None


#: Parameters a model may have that an older checkpoint lacks, by name prefix: they keep
#: their initialisation when the checkpoint starts a run (``initial_weights``).
ADDED_MODULES = ("oscillator_head.",)


def warm_start(model: GarmentDeformer, path: str | Path) -> None:
    """Load a model checkpoint's weights into ``model``; only the parameters of
    :data:`ADDED_MODULES` may be absent from it (the oscillator head starts at zero gain,
    so the warm-started model's output equals the checkpoint's).

    Raises:
        ValueError: unreadable, or a weight is missing, extra or of another shape
            (names the file and the first such key).
    """
    payload = load_checkpoint(path)
    state = payload.get("model_state")
    if not isinstance(state, dict):
        raise ValueError(f"{path}: not a model checkpoint (no model_state)")
    own = model.state_dict()
    for key, value in state.items():
        if key not in own:
            raise ValueError(f"{path}: weight '{key}' has no place in this model "
                             "(initial_weights must come from the same architecture)")
        if tuple(value.shape) != tuple(own[key].shape):
            raise ValueError(f"{path}: weight '{key}' has shape {tuple(value.shape)}, this "
                             f"model's is {tuple(own[key].shape)} (another model config)")
    absent = [key for key in own if key not in state and not key.startswith(ADDED_MODULES)]
    if absent:
        raise ValueError(f"{path}: has no weight '{absent[0]}' of this model "
                         f"({len(absent)} missing)")
    model.load_state_dict(state, strict=False)


def set_stage(model: GarmentDeformer, stage: str) -> None:
    """Freeze/unfreeze for a stage: stage 1 trains all but the physics submodule, the
    physics stages train only the physics submodule."""
    physics = stage != "supervised"
    model.use_physics = physics and model.physics_processor is not None
    for name, parameter in model.named_parameters():
        in_physics = name.startswith("physics_processor.")
        parameter.requires_grad_(in_physics if physics else not in_physics)


def _distributed() -> tuple[int, int]:
    if torch.distributed.is_available() and torch.distributed.is_initialized():
        return torch.distributed.get_rank(), torch.distributed.get_world_size()
    return 0, 1


def rank_share(batches: list, rank: int, world: int) -> list:
    """Rank ``rank``'s batches of an epoch: every ``world``-th, after padding the list
    with its first batches to a multiple of ``world`` (as torch's DistributedSampler
    pads): every rank must take as many steps as the others, since DDP's gradient
    all-reduce waits for all of them."""
    if batches and len(batches) % world:
        padded = -(-len(batches) // world) * world
        batches = [batches[index % len(batches)] for index in range(padded)]
    return batches[rank::world]


def mean_over_ranks(sums: dict[str, float], count: int) -> dict[str, float]:
    """``sums / count`` per key, over the batches of every rank: each rank trains on its
    own share of the epoch, and the stage schedule watches a training metric, so ranks
    that each averaged only their own batches could disagree on a stage switch (one
    rank in the next stage, the other not: DDP then waits forever). With one process,
    the plain mean. Every rank must pass the same keys."""
    names = sorted(sums)
    if _distributed()[1] > 1:
        totals = torch.tensor([float(count)] + [sums[name] for name in names],
                              dtype=torch.float64)
        torch.distributed.all_reduce(totals)
        count, values = int(totals[0]), totals[1:].tolist()
    else:
        values = [sums[name] for name in names]
    return {name: value / max(count, 1) for name, value in zip(names, values, strict=True)}


class Trainer:
    """Train a :class:`GarmentDeformer` on a prepared cache.

    Args:
        config: the run's settings.
        train: training split; validation: optional split evaluated every
            ``config.validate_every`` epochs.
        progress: show progress bars (rank 0 only).
    """

    def __init__(self, config: TrainingConfig, train: PreparedDataset,
                 validation: PreparedDataset | None = None, progress: bool = True):
        self.config = config
        self.train_data = train
        self.validation_data = validation
        self.rank, self.world = _distributed()
        self.progress = progress and self.rank == 0
        self.output = Path(config.output)
        if config.threads:
            torch.set_num_threads(config.threads)
        else:
            from gnngarment.threads import use_idle_cores

            use_idle_cores()
        # Process-wide, as torch has it; a trainer sets it either way, so one run's
        # choice does not leak into the next in the same process.
        torch.use_deterministic_algorithms(config.deterministic)
        torch.manual_seed(config.seed)
        self.model = GarmentDeformer(config.model)
        for dataset in (train, validation):
            if dataset is not None and len(dataset):
                _check_cache_fits(dataset, config.model)
        if config.initial_weights:
            warm_start(self.model, config.initial_weights)
        self.step_module: nn.Module = TrainingStep(self.model)
        self._wrapped_stage: str | None = None
        self.optimiser = torch.optim.Adamax(self.model.parameters(), lr=config.learning_rate)
        self.learning_rate_decay = torch.optim.lr_scheduler.CosineAnnealingLR(
            self.optimiser, T_max=max(config.epochs, 1))
        self.stages = StageSchedule(config.stages)
        self.epoch = 0
        self.global_step = 0
        self.history: list[dict[str, Any]] = []

    # ------------------------------------------------------------------ state
    def checkpoint_path(self) -> Path:
        return self.output / CHECKPOINT_NAME

    def state(self) -> dict[str, Any]:
        # The keys "scheduler" (learning rate) and "schedule" (stages) are the file format
        # of every saved training state, so they keep their names.
        return {**model_payload(self.model), "optimiser": self.optimiser.state_dict(),
                "scheduler": self.learning_rate_decay.state_dict(),
                "schedule": self.stages.state_dict(),
                "epoch": self.epoch, "global_step": self.global_step, "rng": rng_state(),
                "training_config": json.dumps(asdict(self.config)),
                "data_manifest_hash": self.train_data.manifest.get("hash", ""),
                "history": json.dumps(self.history)}

    def resume(self, path: str | Path | None = None) -> None:
        """Restore model, optimiser, learning-rate decay, stage schedule, counters and RNG."""
        payload = load_checkpoint(path or self.checkpoint_path())
        self.model.load_state_dict(payload["model_state"])
        self.stages.load_state_dict(payload["schedule"])
        set_stage(self.model, self.stages.stage)
        self.optimiser.load_state_dict(payload["optimiser"])
        self.learning_rate_decay.load_state_dict(payload["scheduler"])
        self.epoch = int(payload["epoch"])
        self.global_step = int(payload["global_step"])
        self.history = json.loads(payload["history"])
        set_rng_state(payload["rng"])

    # ------------------------------------------------------------------ loop
    def fit(self, resume: bool = False, stop_after: int | None = None) -> dict[str, Any]:
        """Train until the stage schedule is done or ``config.epochs`` is reached.

        A run folder belongs to one run: ``metrics.jsonl`` holds exactly the epochs of
        the run's checkpoint (a fresh run starts it empty; a resumed one drops the lines
        of epochs its checkpoint does not have, e.g. after a kill between the log line
        and the checkpoint write).

        Args:
            resume: continue from ``<output>/last.pt`` if it exists (a fresh run if not).
            stop_after: run at most this many epochs in this call (the run can be
                resumed later exactly as if it had not stopped).

        Returns:
            A summary: final stage, stage switches, last epoch's metrics.

        Raises:
            RunFolderError: ``resume`` is false and ``<output>/last.pt`` of another run
                exists (this trainer has not trained yet).
        """
        from torch.utils.tensorboard import SummaryWriter

        if self.checkpoint_path().is_file():
            if resume:
                self.resume()
            elif self.epoch == 0:
                raise RunFolderError(
                    f"{self.checkpoint_path()}: the output folder holds another run; resume "
                    "it (--resume), or choose another output folder (--set output=...) or "
                    "delete this one to start over")
        if self.rank == 0:
            self._trim_metrics()
        writer = SummaryWriter(str(self.output / "tensorboard")) if self.rank == 0 else None
        last_epoch = self.config.epochs if stop_after is None else min(
            self.config.epochs, self.epoch + stop_after)
        try:
            while self.epoch < last_epoch and self.stages.stage != "done":
                set_stage(self.model, self.stages.stage)
                self.wrap_for_stage()
                metrics = self.train_epoch()
                if self.validation_data is not None and (
                        (self.epoch + 1) % self.config.validate_every == 0):
                    metrics |= {f"val_{k}": v for k, v in self.validate().items()}
                self.epoch += 1
                stage = self.stages.stage
                reason = self.stages.update(metrics, self.epoch)
                self.learning_rate_decay.step()
                metrics |= {"epoch": self.epoch, "stage": stage,
                            "learning_rate": self.learning_rate_decay.get_last_lr()[0]}
                self.history.append(metrics)
                if self.rank == 0:
                    self._log(writer, metrics, reason)
                    save_checkpoint(self.checkpoint_path(), self.state())
                    if reason is not None and stage == "supervised":
                        # The model before the physics stage, for before/after comparisons.
                        save_checkpoint(self.output / SUPERVISED_CHECKPOINT_NAME, self.state())
        finally:
            if writer is not None:
                writer.close()
        return {"epochs": self.epoch, "stage": self.stages.stage,
                "switches": self.stages.switches,
                "last": self.history[-1] if self.history else {}}

    def wrap_for_stage(self) -> None:
        """With several processes, (re)wrap in DDP whenever the trainable set changes:
        DDP only synchronises the parameters that required gradients when it was built.
        Call after :func:`set_stage`."""
        if self.world == 1 or self._wrapped_stage == self.stages.stage:
            return
        self.step_module = nn.parallel.DistributedDataParallel(
            TrainingStep(self.model), find_unused_parameters=True)
        self._wrapped_stage = self.stages.stage

    def train_epoch(self) -> dict[str, float]:
        from tqdm import tqdm

        config = self.config
        self.step_module.train()
        # The batch order is a pure function of (seed, epoch): resuming at an epoch
        # boundary replays exactly the batches an uninterrupted run would see.
        rng = np.random.default_rng([config.seed, self.epoch])
        groups = list(self.train_data.batches(config.pairs_per_batch, config.frames_per_pair,
                                              rng))
        groups = rank_share(groups, self.rank, self.world)
        sums: dict[str, float] = {}
        count = 0
        started = time.perf_counter()
        bar = tqdm(groups, desc=f"epoch {self.epoch + 1} [{self.stages.stage}]",
                   disable=not self.progress, leave=False, unit="batch")
        for items in bar:
            value, terms = self.step(items)
            count += 1
            for name, term in terms.items():
                sums[name] = sums.get(name, 0.0) + term
            sums["loss"] = sums.get("loss", 0.0) + value
            bar.set_postfix(loss=f"{value:.4g}")
        metrics = mean_over_ranks(sums, count)
        metrics["vertex_error_mm"] = 1000 * math.sqrt(metrics.get("vertex", 0.0))
        metrics["seconds"] = time.perf_counter() - started
        return metrics

    def step(self, items: list[tuple[str, np.ndarray]]) -> tuple[float, dict[str, float]]:
        """One optimiser step of the current stage on ``items`` (sequence name, frame
        indices). Returns the total loss and its terms.

        Raises:
            FloatingPointError: the loss is not finite.
        """
        config = self.config
        batch = self.train_data.batch(items)
        output = self.step_module(batch)
        total, terms = stage_loss(output, batch, self.stages.stage, config.losses,
                                  config.stages, config.collision_margin)
        value = total.item()
        if not math.isfinite(value):
            raise FloatingPointError(f"loss became {value} at epoch {self.epoch + 1}"
                                     f" (terms {terms}); lower the learning rate")
        self.optimiser.zero_grad(set_to_none=True)
        total.backward()
        self.optimiser.step()
        self.global_step += 1
        return value, terms

    @torch.no_grad()
    def validate(self) -> dict[str, float]:
        """Mean vertex error (mm, RMS per vertex) and collision term on the validation
        split, every frame of every sequence (with several processes each evaluates
        every ``world``-th sequence, and all get the mean over all of them)."""
        from gnngarment.training.objective import loss_terms

        data = self.validation_data
        assert data is not None
        self.model.eval()
        watched = ["vertex", "collision"]
        # Every key present even on a rank with no sequence: mean_over_ranks sums by key.
        sums = dict.fromkeys(watched, 0.0)
        count = 0
        for name in data.sequence_names[self.rank::self.world]:
            frames = np.arange(data.frame_counts[name])
            for start in range(0, len(frames), self.config.frames_per_pair):
                chunk = frames[start:start + self.config.frames_per_pair]
                batch = data.batch([(name, chunk)])
                output = TrainingStep(self.model)(batch)
                terms = loss_terms(output, batch, watched, self.config.collision_margin)
                for key, value in terms.items():
                    sums[key] += float(value) * len(chunk)
                count += len(chunk)
        metrics = mean_over_ranks(sums, count)
        metrics["vertex_error_mm"] = 1000 * math.sqrt(metrics["vertex"])
        return metrics

    def _log(self, writer, metrics: dict[str, Any], reason: str | None) -> None:
        for name, value in metrics.items():
            if isinstance(value, (int, float)) and name != "epoch":
                writer.add_scalar(name, value, self.epoch)
        line = (f"epoch {self.epoch} [{metrics['stage']}] loss {metrics.get('loss', 0):.4g} "
                f"vertex {metrics.get('vertex_error_mm', 0):.1f} mm")
        if "val_vertex_error_mm" in metrics:
            line += f", val {metrics['val_vertex_error_mm']:.1f} mm"
        if self.progress:
            print(line, flush=True)
        if reason is not None:
            print(f"stage switch after epoch {self.epoch}: {metrics['stage']} -> "
                  f"{self.stages.stage} ({reason})", flush=True)
        (self.output / METRICS_NAME).parent.mkdir(parents=True, exist_ok=True)
        with open(self.output / METRICS_NAME, "a") as stream:
            stream.write(json.dumps({**metrics, "switch": reason}) + "\n")

    def _trim_metrics(self) -> None:
        """Keep only the ``metrics.jsonl`` lines of epochs up to :attr:`epoch` (none for
        a fresh run), so that the file never mixes runs or repeats an epoch."""
        path = self.output / METRICS_NAME
        if not path.is_file():
            return
        kept = []
        for line in path.read_text().splitlines():
            try:
                epoch = int(json.loads(line)["epoch"])
            except (ValueError, KeyError, TypeError):
                continue  # a line cut short by a kill
            if epoch <= self.epoch:
                kept.append(line + "\n")
        atomic_write_bytes(path, "".join(kept).encode())
