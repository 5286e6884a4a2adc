"""Episode bookkeeping and a step's reward features and info, computed by hand."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from explaindrive.commands import Command
from explaindrive.env.episode import Episode, StepRecord
from explaindrive.env.perception import CrossingReading, Leader, Percept
from explaindrive.env.reward import RECIPES, reward_terms
from explaindrive.env.state import LightState
from explaindrive.env.sumo_process import Motion
from explaindrive.env.violations import Violations


def episode(schedule: list[tuple[float, Command]]) -> Episode:
    nothing: Any = None
    return Episode(Command.FAST, schedule, 10.0, perception=nothing, judge=nothing)


def test_scheduled_commands_switch_when_due() -> None:
    ep = episode([(2.0, Command.STOP), (2.0, Command.COMFORT), (5.0, Command.FAST)])
    ep.apply_schedule()
    assert ep.command is Command.FAST
    ep.steps = 2
    ep.apply_schedule()  # both switches at 2 s apply, the later one wins
    assert ep.command is Command.COMFORT and ep.schedule == [(5.0, Command.FAST)]
    assert ep.time_s == 2.0


def step(leader: Leader | None, real: Leader | None) -> StepRecord:
    motion = Motion(10.0, collided=False, arrived=False, ego=None)
    return StepRecord(Command.FAST, 1, 1.0, -0.5, motion, leader, real, 13.89,
                      Violations(True, False, "signal"))  # fmt: skip


def test_features_are_taken_to_the_effective_leader() -> None:
    real = Leader(30.0, 6.0, 5.0, False)
    rec = step(Leader(20.0, 0.0, 0.0, True), real)
    f = rec.features()
    assert f.ttc_s == pytest.approx(2.0)  # 20 m closing at 10 m/s
    assert f.headway_s == pytest.approx(2.0)  # a zero-length leader 20 m ahead at 10 m/s
    assert f.real_headway_s == pytest.approx((30.0 + 5.0) / 10.0)
    assert f.violation and f.stop_reason is None and f.closing_speed_mps == 10.0
    assert step(None, None).features().ttc_s == math.inf


@pytest.mark.parametrize(
    ("violations", "traffic"),
    [
        (Violations(False, False, "yield_junction", yield_violation=True), -10.0),
        (Violations(False, True, "crossing"), -10.0),
        (Violations(False, False, "yield_junction"), 0.0),
    ],
)
def test_a_yield_violation_is_charged_as_the_other_violations(
    violations: Violations, traffic: float
) -> None:
    motion = Motion(10.0, collided=False, arrived=False, ego=None)
    rec = StepRecord(Command.FAST, 1, 1.0, -0.5, motion, None, None, 13.89, violations)
    f = rec.features()
    assert f.violation is (traffic < 0.0)
    # R_traffic: -r_unsafe (10) for a violation while moving, 0 otherwise
    assert reward_terms(Command.FAST, f, RECIPES["passenger"]).traffic == traffic


def test_the_info_reports_the_step() -> None:
    ep = episode([])
    ep.steps, ep.pos_m = 4, 52.0
    rec = step(None, Leader(30.0, 6.0, 5.0, False))
    obs = np.array([0, 10, 13.89, 30, 4, 80, 2, 200], dtype=np.float32)
    crossings = CrossingReading(200.0, {})
    ep.seen = Percept(obs, None, None, (), crossings, LightState.RED)
    features = rec.features()
    terms = reward_terms(Command.FAST, features, RECIPES["paper"]).as_dict()
    info = rec.info(ep, obs, 13.89, features, terms)
    assert info["time_s"] == 4.0 and info["distance_m"] == 42.0
    assert info["real_ttc_s"] == pytest.approx(30.0 / 4.0)
    assert info["light_state"] == "red" and info["light_gap_m"] == 80.0
    # the info reports the light's true colour, also where the ego is shown another
    shown_green = obs.copy()
    shown_green[6] = 0
    ep.seen = Percept(shown_green, None, None, (), crossings, LightState.YELLOW)
    assert rec.info(ep, shown_green, 13.89, features, terms)["light_state"] == "yellow"
    assert info["red_light_run"] and not info["ped_violation"] and not info["speeding"]
    assert info["site"] == "signal"
    assert info["gap_m"] == math.inf and info["reward_terms"] == terms
