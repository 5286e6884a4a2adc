"""The safety mask the environment exposes to masked-action learners."""

from __future__ import annotations

from typing import Any

import numpy as np

from explaindrive.env.actions import action_index
from explaindrive.env.safety import runtime_mask


def test_the_mask_follows_the_true_state_and_the_command(make_env: Any) -> None:
    env = make_env(traffic_level=0.5, obs_noise=(2.0, 1.0))
    obs, info = env.reset(seed=4)
    assert info["action_mask"].dtype == np.bool_ and info["action_mask"].shape == (7,)
    # standing at the entry, the braking actions and 0 m/s all leave the ego standing: safe
    assert info["action_mask"][:4].all()
    for _ in range(3):
        obs, _, _, _, info = env.step(action_index(3))
    assert info["speed_mps"] == 9.0
    np.testing.assert_array_equal(info["action_mask"], runtime_mask(info["true_obs"]))
    assert not np.array_equal(obs, info["true_obs"])  # the driver sees noise, the mask does not
    env.set_command("stop")
    # under STOP at 9 m/s only -3 brings the standstill a hardest-braking step closer
    assert env.action_masks().tolist() == [True] + [False] * 6
    assert info["action_mask"].tolist() != env.action_masks().tolist()  # info is a snapshot
