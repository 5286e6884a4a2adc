"""The policies shipped with the package: they load, carry their cards, and drive."""

from __future__ import annotations

import pytest

from explaindrive.agent.controller import MergedController, QPolicy, shipped_policy_path
from explaindrive.env.metrics import EpisodeMetrics
from explaindrive.env.urban_drive import UrbanDriveEnv


@pytest.mark.parametrize("name", ["fast", "comfort"])
def test_card_describes_the_training(name: str) -> None:
    policy = QPolicy.load(shipped_policy_path(name))
    card = policy.card
    assert card["name"] == name and card["mode"] == name
    assert card["config"]["hidden_sizes"] == [128, 128]
    for key in ("episodes", "env_steps", "wall_time_s", "steps_per_s", "git_commit"):
        assert card[key], key
    assert card["evaluation"], "the card carries its evaluation figures"


@pytest.mark.parametrize("use_shield", [True, False])
@pytest.mark.parametrize("name", ["fast", "comfort"])
def test_shipped_policy_drives_a_short_episode_safely(name: str, use_shield: bool) -> None:
    """As shipped (through the controller's shield) and as the bare network."""
    policy = QPolicy.load(shipped_policy_path(name))
    controller = MergedController(policy, policy, name, use_shield=use_shield)
    env = UrbanDriveEnv(traffic_level=1.0, max_steps=150)
    metrics = EpisodeMetrics()
    try:
        obs, _ = env.reset(seed=0, options={"command": name})
        done = False
        while not done:
            obs, reward, terminated, truncated, info = env.step(controller.act(obs))
            metrics.update(info, reward)
            done = terminated or truncated
    finally:
        env.close()
    res = metrics.result()
    assert res.collisions == res.red_light_runs == res.ped_violations == res.speeding_steps == 0
    assert res.distance_m > 300.0  # it drives, it does not just stand still
