"""The run's counters and their checkpoint form, against a checkpoint written by hand."""

from __future__ import annotations

import csv
import functools
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import torch

from explaindrive.agent.checkpoint import save_checkpoint
from explaindrive.agent.controller import QPolicy
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.run_state import RunState
from explaindrive.agent.trainer import train
from tests.agent.fake_drive_env import FakeDriveEnv
from tests.agent.test_trainer import tiny

OLD = "a" * 40
NEW = "b" * 40


@pytest.fixture(autouse=True)
def _keep_torch_rng() -> Iterator[None]:
    """Loading a state sets torch's global RNG: give the other tests theirs back."""
    saved = torch.get_rng_state()
    yield
    torch.set_rng_state(saved)


def saved_state() -> dict[str, object]:
    """A checkpoint's ``trainer`` entry in the format runs write, with numbers set by hand:
    4 episodes done in 80 steps, episode 4 under way when it was saved."""
    return {
        "env_steps": 80,
        "episodes_done": 4,
        "next_episode": 5,
        "pending": [4],
        "update_debt": 0.5,
        "wall_time_s": 12.5,
        "reset_failures": 2,
        "lost_rounds": 1,
        "clean_streak": 3,
        "recent_returns": [1.0, 2.0, 3.0],
        "source_commits": [OLD],
        "rng": np.random.default_rng(7).bit_generator.state,
        "torch_rng": torch.manual_seed(3).get_state(),
    }


def test_a_saved_state_loads_and_saves_back_unchanged() -> None:
    saved = saved_state()
    state = RunState.start(seed=0, window=3, commit=OLD)
    state.load_state_dict(saved)
    assert (state.env_steps, state.episodes_done, state.next_episode) == (80, 4, 5)
    assert (list(state.pending), state.update_debt, state.wall_time_s) == ([4], 0.5, 12.5)
    assert (state.reset_failures, state.lost_rounds, state.clean_streak) == (2, 1, 3)
    assert state.mean_return == 2.0  # (1 + 2 + 3) / 3
    assert state.rng.integers(0, 1000) == np.random.default_rng(7).integers(0, 1000)
    torch.manual_seed(0)  # the next load sets it back
    state.load_state_dict(saved)
    again = state.state_dict()
    assert torch.equal(again.pop("torch_rng"), saved.pop("torch_rng"))  # type: ignore[arg-type]
    assert again == saved  # same keys, same values: the commit of the run was the last one


def test_in_flight_episodes_are_saved_ahead_of_the_pending_ones() -> None:
    state = RunState.start(seed=0, window=3, commit=None)
    state.pending.extend([7, 8])
    assert state.state_dict(in_flight=[2, 5])["pending"] == [2, 5, 7, 8]


def test_a_resume_adds_its_commit_and_keeps_the_window() -> None:
    state = RunState.start(seed=0, window=2, commit=NEW)
    state.load_state_dict(saved_state())
    assert state.source_commits == [OLD, NEW]
    assert list(state.recent_returns) == [2.0, 3.0]  # the last 2 of the 3 saved


def test_a_state_saved_without_the_later_counters_counts_them_zero() -> None:
    saved = saved_state()
    for key in ("reset_failures", "lost_rounds", "clean_streak", "source_commits"):
        del saved[key]
    state = RunState.start(seed=0, window=3, commit=NEW)
    state.load_state_dict(saved)
    assert (state.reset_failures, state.lost_rounds, state.clean_streak) == (0, 0, 0)
    assert state.source_commits == [None, NEW]  # where the run started is unknown


def test_a_run_resumes_from_a_checkpoint_written_by_hand(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    config = tiny(episodes=6)
    save_checkpoint(
        tmp_path / "checkpoints", config=config, learner_state=D3QNLearner(config).state_dict(),
        trainer_state=saved_state(), replay_state=None,
    )  # fmt: skip
    monkeypatch.setattr("explaindrive.agent.trainer.git_commit", lambda: NEW)
    factory = functools.partial(FakeDriveEnv, max_steps=20)
    result = train(config, tmp_path, env_factory=factory, resume=True)
    # episodes 4 (pending) and 5 (next) of 20 steps each; the 40 steps after 80 (> 50
    # learning starts) owe 40 / 2 = 20 updates, with the saved 0.5 still owed at the end
    assert (result.episodes, result.env_steps, result.updates) == (6, 120, 20)
    assert result.wall_time_s > 12.5
    with (tmp_path / "episodes.csv").open(newline="") as f:
        table = list(csv.DictReader(f))
    assert [(r["episode"], r["env_steps"]) for r in table] == [("4", "100"), ("5", "120")]
    card = QPolicy.load(result.policy_path).card
    assert card["git_commits"] == [OLD, NEW]
    assert (card["reset_failures"], card["lost_rounds"]) == (2, 1)
    mean = (3.0 + float(table[0]["return"]) + float(table[1]["return"])) / 3  # window of 3
    assert card["final_mean_return"] == pytest.approx(mean, abs=1e-4)
