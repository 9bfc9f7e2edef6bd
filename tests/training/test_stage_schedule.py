from __future__ import annotations

from gnngarment.training.config import StageConfig
from gnngarment.training.stage_schedule import StageSchedule


def test_plateau_rule_switches_with_a_reason() -> None:
    schedule = StageSchedule(StageConfig(supervised_window=2, supervised_threshold=0.04,
                                         collision_window=1, collision_threshold=0.05))
    # 10% per epoch over 2 epochs: keeps going.
    for epoch, vertex in enumerate([1.0, 0.9, 0.81, 0.73], start=1):
        assert schedule.update({"vertex": vertex}, epoch) is None
    # 0.73 -> 0.72 -> 0.715: 2% over the window: switch.
    assert schedule.update({"vertex": 0.72}, 5) is None
    reason = schedule.update({"vertex": 0.715}, 6)
    assert reason is not None and "vertex improved" in reason and "over the last 2" in reason
    assert schedule.stage == "physics" and schedule.history == []
    assert schedule.update({"collision": 1.0}, 7) is None
    assert schedule.update({"collision": 0.99}, 8) is not None
    assert schedule.stage == "physics_strain"
    assert schedule.switches[0]["epoch"] == 6 and schedule.switches[1]["to"] == "physics_strain"


def test_epoch_limits_and_state_round_trip() -> None:
    schedule = StageSchedule(StageConfig(max_epochs=[1, 1, 1]))
    assert "limit" in schedule.update({"vertex": 1.0}, 1)
    assert "limit" in schedule.update({"collision": 1.0}, 2)
    assert "limit" in schedule.update({"collision": 1.0}, 3)
    assert schedule.stage == "done" and schedule.update({}, 4) is None
    copy = StageSchedule(StageConfig())
    copy.load_state_dict(schedule.state_dict())
    assert copy.state_dict() == schedule.state_dict()
