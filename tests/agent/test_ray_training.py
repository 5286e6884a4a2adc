"""Training with the env workers as Ray actors on a local Ray (``train --ray``)."""

from __future__ import annotations

import csv
import functools
import os
from pathlib import Path

import pytest

from explaindrive.agent.controller import QPolicy
from explaindrive.agent.trainer import train
from tests.agent.fake_drive_env import FakeDriveEnv
from tests.agent.test_trainer import TINY, tiny

pytest.importorskip("ray")
pytestmark = pytest.mark.slow

FACTORY = functools.partial(FakeDriveEnv, max_steps=20)


class DiesOnce(FakeDriveEnv):
    """Kills its process at its third reset, once (a marker file remembers)."""

    def __init__(self, marker: str, **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.marker = Path(marker)
        self.resets = 0

    def reset(self, *, seed=None, options=None):  # type: ignore[no-untyped-def]
        self.resets += 1
        if self.resets == 3 and self._first_to_die():
            os._exit(1)
        return super().reset(seed=seed, options=options)

    def _first_to_die(self) -> bool:
        """Create the marker atomically: both workers reach their third reset at about the
        same time, and only one of them may die."""
        try:
            os.close(os.open(self.marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        except FileExistsError:
            return False
        return True


def rows(out: Path) -> list[dict[str, str]]:
    with (out / "episodes.csv").open(newline="") as f:
        return list(csv.DictReader(f))


def test_two_ray_workers_train_checkpoint_and_resume(tmp_path: Path) -> None:
    config = tiny(episodes=6, num_envs=2, checkpoint_every_episodes=2)
    result = train(config, tmp_path, env_factory=FACTORY, use_ray=True)
    assert (result.episodes, result.env_steps) == (6, 120)
    assert result.updates == (120 - TINY["learning_starts"]) // 2  # one per 2 after 50
    assert {r["env"] for r in rows(tmp_path)} == {"0", "1"}  # both workers filled the buffer
    assert (tmp_path / "checkpoints" / "checkpoint.pt").is_file()
    resumed = train(config.replace(episodes=9), tmp_path, env_factory=FACTORY, resume=True,
                    use_ray=True)  # fmt: skip
    assert (resumed.episodes, resumed.env_steps) == (9, 180)
    assert sorted(int(r["episode"]) for r in rows(tmp_path)) == list(range(9))


def test_a_ray_worker_that_dies_is_restarted_and_its_episode_played_again(tmp_path: Path) -> None:
    factory = functools.partial(DiesOnce, str(tmp_path / "died"), max_steps=20)
    config = tiny(episodes=6, num_envs=2)
    result = train(config, tmp_path / "run", env_factory=factory, use_ray=True)
    assert (tmp_path / "died").exists()
    assert result.episodes == 6
    assert sorted(int(r["episode"]) for r in rows(tmp_path / "run")) == list(range(6))
    assert QPolicy.load(result.policy_path).card["lost_rounds"] == 1
    log = (tmp_path / "run" / "train.log").read_text()
    assert "died" in log and "will be played again" in log
