"""The environment replays the recorded episodes step by step (observations, rewards,
termination and info within 1e-6): its structure may change, its behaviour may not."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.env.golden import CASES, assert_same, load_golden, record


@pytest.fixture(scope="module")
def golden() -> dict[str, list[dict[str, Any]]]:
    return load_golden()


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_env_replays_the_recorded_episode(
    name: str, make_env: Any, golden: dict[str, list[dict[str, Any]]], tmp_path: Path
) -> None:
    want = golden[name]
    got = record(make_env, CASES[name], tmp_path)
    assert len(got) == len(want), f"{name}: {len(got) - 1} steps, recorded {len(want) - 1}"
    assert_same(got, want, name)


def test_the_comparison_catches_a_changed_value() -> None:
    step = {"obs": [1.0, 2.0], "reward": -0.5, "info": {"light_state": "red", "gap_m": 3.0}}
    assert_same(step, step)
    for changed in ({**step, "obs": [1.0, 2.001]}, {**step, "reward": -0.5001},
                    {**step, "info": {"light_state": "green", "gap_m": 3.0}}):  # fmt: skip
        with pytest.raises(AssertionError):
            assert_same(changed, step)
    assert_same({**step, "reward": -0.5 + 1e-9}, step)
