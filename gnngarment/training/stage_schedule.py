"""The two-stage schedule (blueprint Sec. 3.4) as a small serialisable state machine.

Stage ``supervised``: every parameter but the physics submodule, supervised losses.
Stage ``physics``: only the physics submodule, vertex/edge ×0.1, normal off, collision
and gravity on. Stage ``physics_strain``: as ``physics`` plus stretch and shear.
A stage ends when its watched metric improved by less than a threshold over a window
of epochs (the blueprint's plateau rule), or at its epoch limit; the reason is kept.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from gnngarment.training.config import TRAINED_STAGES, StageConfig

STAGES = (*TRAINED_STAGES, "done")
#: The metric each stage watches for its plateau.
WATCHED = {"supervised": "vertex", "physics": "collision", "physics_strain": "collision"}


@dataclass
class StageSchedule:
    """Which stage training is in, and the metric history that decides switches."""

    config: StageConfig
    stage: str = "supervised"
    history: list[float] = field(default_factory=list)
    epochs_in_stage: int = 0
    switches: list[dict] = field(default_factory=list)

    def window_and_threshold(self) -> tuple[int, float]:
        config = self.config
        return {"supervised": (config.supervised_window, config.supervised_threshold),
                "physics": (config.collision_window, config.collision_threshold),
                "physics_strain": (config.strain_window, config.strain_threshold)}[self.stage]

    def update(self, metrics: dict[str, float], epoch: int) -> str | None:
        """Record an epoch's metrics; switch stage if the plateau rule fires.

        Returns:
            The reason of the switch, or ``None`` if the stage goes on.
        """
        if self.stage == "done":
            return None
        self.history.append(float(metrics[WATCHED[self.stage]]))
        self.epochs_in_stage += 1
        window, threshold = self.window_and_threshold()
        reason = None
        if len(self.history) > window:
            before, now = self.history[-window - 1], self.history[-1]
            reduction = (before - now) / before if before > 0 else 0.0
            if reduction < threshold:
                reason = (f"{WATCHED[self.stage]} improved {100 * reduction:.1f}% over the last "
                          f"{window} epochs (< {100 * threshold:.0f}%)")
        limit = self.config.max_epochs[STAGES.index(self.stage)]
        if reason is None and limit and self.epochs_in_stage >= limit:
            reason = f"stage epoch limit {limit} reached"
        if reason is not None:
            previous = self.stage
            self.stage = STAGES[STAGES.index(self.stage) + 1]
            self.switches.append({"epoch": epoch, "from": previous, "to": self.stage,
                                  "reason": reason})
            self.history, self.epochs_in_stage = [], 0
        return reason

    def state_dict(self) -> dict:
        return {"stage": self.stage, "history": list(self.history),
                "epochs_in_stage": self.epochs_in_stage, "switches": list(self.switches)}

    def load_state_dict(self, state: dict) -> None:
        self.stage = state["stage"]
        self.history = list(state["history"])
        self.epochs_in_stage = int(state["epochs_in_stage"])
        self.switches = list(state["switches"])
