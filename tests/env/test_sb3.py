"""Stable-Baselines3 on the env: the documented MaskablePPO example runs, and masked learning
sees the shield's mask and the curriculum's stops."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import explaindrive
from explaindrive.env import state as S
from explaindrive.env.safety import runtime_mask
from explaindrive.env.wrappers import CommandSchedule, RandomTraffic, SeedPool, StopInjection

sb3_contrib = pytest.importorskip("sb3_contrib")
DOCS = Path(__file__).resolve().parents[2] / "docs" / "environment.md"


def test_the_documented_example_trains_and_saves(tmp_path: Path, monkeypatch: Any) -> None:
    text = DOCS.read_text(encoding="utf-8")
    block = re.search(r"<!-- sb3-example[^>]*-->\n```python\n(.*?)```", text, re.S)
    assert block, "docs/environment.md lost its sb3-example block"
    code = block.group(1)
    small = {  # the same code on a budget of 256 steps and 2 warm-ups
        "total_timesteps=200_000": "total_timesteps=256",
        "seed=0)": "seed=0, n_steps=256, batch_size=64, n_epochs=1)",
        "size=250": "size=2",
    }
    for old, new in small.items():
        assert old in code, f"the example no longer has {old!r}"
        code = code.replace(old, new)
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, Any] = {}
    exec(compile(code, str(DOCS), "exec"), namespace)  # the docs' own example
    assert (tmp_path / "maskable_ppo.zip").is_file()
    assert namespace["model"].num_timesteps == 256
    assert namespace["info"]["action_mask"][int(namespace["action"])]  # a masked choice


def test_masked_learning_sees_the_shields_mask_and_the_curriculums_stops() -> None:
    env = gym.make(explaindrive.ENV_ID, max_steps=100)
    env = CommandSchedule(
        StopInjection(RandomTraffic(SeedPool(env, size=2), (0.5, 1.0)), gap_s=(5.0, 10.0)),
        ("fast", "comfort"),
    )
    try:
        model = sb3_contrib.MaskablePPO("MlpPolicy", env, seed=0, n_steps=256, batch_size=64,
                                        n_epochs=2)  # fmt: skip
        before = [p.detach().clone() for p in model.policy.parameters()]
        model.learn(256)
    finally:
        env.close()
    buf = model.rollout_buffer
    obs = buf.observations.reshape(-1, S.STATE_DIM)
    masks = buf.action_masks.reshape(-1, 7).astype(bool)
    actions = buf.actions.reshape(-1).astype(int)
    assert len(obs) == 256
    np.testing.assert_array_equal(masks, runtime_mask(obs))  # the shield's rule, state by state
    assert masks[np.arange(256), actions].all()  # the learner only took allowed actions
    assert not masks.all()  # and the mask did forbid some
    assert (obs[:, S.CMD] == 2).sum() >= 5  # injected stop commands reached the observations
    after = list(model.policy.parameters())
    assert any(not np.array_equal(a, b.detach()) for a, b in zip(before, after, strict=True))
