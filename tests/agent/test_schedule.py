"""The paper's episode schedule."""

from __future__ import annotations

import numpy as np

from explaindrive.agent.config import PAPER, SEED_POOL_BASE
from explaindrive.agent.schedule import plan_episode, stop_schedule
from explaindrive.commands import Command


def test_even_episodes_interleave_stop_odd_hold_the_primary() -> None:
    cfg = PAPER.replace(mode="comfort")
    even, odd = plan_episode(cfg, 10), plan_episode(cfg, 11)
    assert even.has_stops and not odd.has_stops
    labels = [c for _, c in even.command_schedule]
    assert labels[0::2] == ["stop"] * len(labels[0::2])
    assert labels[1::2] == ["comfort"] * len(labels[1::2])
    times = [t for t, _ in even.command_schedule]
    assert times == sorted(times) and times[0] >= cfg.stop_gap_s[0]
    assert odd.reset_options() == {
        "command": "comfort", "traffic_level": odd.traffic_level, "command_schedule": []
    }  # fmt: skip


def test_plans_are_reproducible_and_vary() -> None:
    assert plan_episode(PAPER, 4) == plan_episode(PAPER, 4)
    plans = [plan_episode(PAPER, i) for i in range(40)]
    assert len({p.seed for p in plans}) == 40
    assert {p.traffic_level for p in plans} == set(PAPER.traffic_levels)
    assert plan_episode(PAPER.replace(seed=1), 4).seed != plan_episode(PAPER, 4).seed


def test_stop_schedule_gaps_and_durations() -> None:
    sched = stop_schedule(np.random.default_rng(0), Command.FAST, (10, 10), (4, 4), 40.0)
    assert sched == ((10.0, "stop"), (14.0, "fast"), (24.0, "stop"), (28.0, "fast"),
                     (38.0, "stop"), (42.0, "fast"))  # fmt: skip


def test_seed_pool_bounds_the_episode_seeds() -> None:
    cfg = PAPER.replace(seed_pool=3)
    seeds = {plan_episode(cfg, i).seed for i in range(60)}
    assert seeds == {SEED_POOL_BASE, SEED_POOL_BASE + 1, SEED_POOL_BASE + 2}


def test_observation_noise_is_drawn_per_episode_within_its_bounds() -> None:
    cfg = PAPER.replace(obs_noise_max=(3.0, 0.9), noisy_share=0.5)
    plans = [plan_episode(cfg, i) for i in range(200)]
    noisy = [p for p in plans if p.obs_noise != (0.0, 0.0)]
    assert 80 <= len(noisy) <= 120  # about half
    assert len({p.obs_noise for p in noisy}) == len(noisy)
    assert all(0.0 <= m <= 3.0 and 0.0 <= s <= 0.9 for m, s in (p.obs_noise for p in noisy))
    assert plan_episode(cfg, 7) == plans[7]
    assert noisy[0].reset_options()["obs_noise"] == list(noisy[0].obs_noise)
    assert all(p.obs_noise == (0.0, 0.0) for p in map(
        lambda i: plan_episode(cfg.replace(noisy_share=0.0), i), range(20)
    ))  # fmt: skip
    # the noise has its own generator: the rest of the plan is the one without noise
    plain = plan_episode(PAPER, 7)
    assert (plain.seed, plain.traffic_level, plain.command_schedule) == (
        plans[7].seed, plans[7].traffic_level, plans[7].command_schedule,
    )  # fmt: skip
    assert "obs_noise" not in plain.reset_options()


def test_the_speeds_can_have_a_noisy_share_of_their_own() -> None:
    cfg = PAPER.replace(obs_noise_max=(3.0, 0.9), noisy_share=0.5)
    both = [plan_episode(cfg, i).obs_noise for i in range(200)]
    apart = [plan_episode(cfg.replace(speed_noisy_share=1.0), i).obs_noise for i in range(200)]
    # the distances keep their draws; every episode's speeds are noisy, with the same sd
    # where the distances are noisy too
    assert [m for m, _ in apart] == [m for m, _ in both]
    assert sum(s > 0.0 for _, s in apart) == 199  # one draw rounds to 0.0 m/s (as in both)
    assert sum(s > 0.0 for _, s in both) == 101
    assert all(a == b for a, b in zip(apart, both, strict=True) if b != (0.0, 0.0))
    none = [plan_episode(cfg.replace(speed_noisy_share=0.0), i).obs_noise for i in range(200)]
    assert [m for m, _ in none] == [m for m, _ in both] and all(s == 0.0 for _, s in none)
    # the speeds' own share: about a quarter with 0.25
    quarter = [plan_episode(cfg.replace(speed_noisy_share=0.25), i).obs_noise for i in range(200)]
    assert 35 <= sum(s > 0.0 for _, s in quarter) <= 65
