"""The curriculum wrappers: the options they give each episode, on an env that records them."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from explaindrive.agent import schedule
from explaindrive.env import curriculum
from explaindrive.env.wrappers import (
    SEED_POOL_BASE,
    CommandSchedule,
    RandomTraffic,
    SeedPool,
    StopInjection,
)


class Recorder(gym.Env[np.ndarray, int]):
    """Records the seed and options of every reset."""

    observation_space = gym.spaces.Box(0.0, 1.0, (1,))
    action_space = gym.spaces.Discrete(2)

    def __init__(self) -> None:
        self.resets: list[tuple[int | None, dict[str, Any]]] = []

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        self.resets.append((seed, dict(options or {})))
        return np.zeros(1, dtype=np.float32), {}


def run(env: gym.Env, episodes: int, seed: int = 0) -> list[tuple[int | None, dict[str, Any]]]:
    env.reset(seed=seed)
    for _ in range(episodes - 1):
        env.reset()
    return env.unwrapped.resets


def test_stops_come_in_every_other_episode_and_return_to_its_command() -> None:
    resets = run(CommandSchedule(StopInjection(Recorder()), ("comfort",)), 4)
    with_stops = [bool(opts.get("command_schedule")) for _, opts in resets]
    assert with_stops == [True, False, True, False]
    switches = resets[0][1]["command_schedule"]
    assert [c for _, c in switches] == ["stop", "comfort"] * (len(switches) // 2)
    times = [t for t, _ in switches]
    assert 15.0 <= times[0] <= 60.0 and times == sorted(times) and times[-2] < 900.0
    gaps = np.diff(times)
    assert all(5.0 <= g <= 15.0 for g in gaps[0::2]) and all(15.0 <= g <= 60.0 for g in gaps[1::2])


def test_the_wrapper_draws_the_trainers_schedule() -> None:
    assert schedule.stop_schedule is curriculum.stop_schedule  # one rule, two users
    resets = run(StopInjection(Recorder(), every=1), 1, seed=5)
    want = curriculum.stop_schedule(np.random.default_rng([5, 102]), curriculum.Command.FAST,
                                    (15.0, 60.0), (5.0, 15.0), 900.0)  # fmt: skip
    assert resets[0][1]["command_schedule"] == [list(s) for s in want]


def test_commands_levels_and_seeds_are_drawn_per_episode() -> None:
    env = CommandSchedule(RandomTraffic(SeedPool(Recorder(), size=3)), ("fast", "comfort"))
    resets = run(env, 40)
    assert {opts["command"] for _, opts in resets} == {"fast", "comfort"}
    assert {opts["traffic_level"] for _, opts in resets} == {0.5, 0.75, 1.0, 1.25, 1.5}
    assert {seed for seed, _ in resets} == {SEED_POOL_BASE, SEED_POOL_BASE + 1, SEED_POOL_BASE + 2}
    again = CommandSchedule(RandomTraffic(SeedPool(Recorder(), size=3)), ("fast", "comfort"))
    assert run(again, 40) == resets  # the same seed, the same episodes


def test_explicit_options_are_kept() -> None:
    env = StopInjection(RandomTraffic(CommandSchedule(Recorder(), ("comfort",)), (1.25,)))
    env.reset(seed=0, options={"command": "stop", "traffic_level": 0.5, "command_schedule": []})
    assert env.unwrapped.resets[0][1] == {"command": "stop", "traffic_level": 0.5,
                                          "command_schedule": []}  # fmt: skip
    env.reset()
    assert env.unwrapped.resets[1][1] == {"command": "comfort", "traffic_level": 1.25}


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda e: CommandSchedule(e, ()), "at least one command"),
        (lambda e: CommandSchedule(e, ("fastest",)), "fastest"),
        (lambda e: RandomTraffic(e, (3.0,)), "traffic"),
        (lambda e: StopInjection(e, gap_s=(10.0, 5.0)), "gap_s"),
        (lambda e: StopInjection(e, every=0), "every"),
        (lambda e: SeedPool(e, 0), "size"),
        (lambda e: SeedPool(RandomTraffic(e), 3), "SeedPool goes inside"),
    ],
)
def test_bad_settings_are_refused(make: Any, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        make(Recorder())
