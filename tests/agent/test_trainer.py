"""The training loop on the fake env: outputs, checkpoint, resume, and a killed run."""

from __future__ import annotations

import csv
import functools
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from explaindrive.agent import trainer as trainer_module
from explaindrive.agent.checkpoint import CheckpointError, load_checkpoint
from explaindrive.agent.config import SEED_POOL_BASE, TrainConfig, preset
from explaindrive.agent.controller import QPolicy
from explaindrive.agent.rollout import NStepQueue
from explaindrive.agent.run_log import moving_average
from explaindrive.agent.schedule import plan_episode
from explaindrive.agent.trainer import train
from explaindrive.env.safety import runtime_mask
from tests.agent.fake_drive_env import FakeDriveEnv

EPISODE_STEPS = 20
FACTORY = functools.partial(FakeDriveEnv, max_steps=EPISODE_STEPS)
TINY = dict(
    num_envs=1, hidden_sizes=[32, 32], buffer_size=5_000, batch_size=16, learning_starts=50,
    train_frequency=2, target_update_interval=10, eps_decay_steps=150, checkpoint_every_episodes=4,
    log_every_updates=10, stop_gap_s=[3, 5], stop_duration_s=[2, 3], schedule_horizon_s=20.0,
    moving_average_window=3, stop_when_safe=None,
)  # fmt: skip


def tiny(**changes: object) -> TrainConfig:
    return preset("safe").replace(**{**TINY, **changes})


def rows(out: Path) -> list[dict[str, str]]:
    with (out / "episodes.csv").open(newline="") as f:
        return list(csv.DictReader(f))


def test_tiny_run_writes_every_output(tmp_path: Path) -> None:
    result = train(tiny(episodes=10), tmp_path, env_factory=FACTORY)
    # 10 fixed-length episodes; updates start at 50 transitions, one per 2:
    # the calls at 50..200 transitions add 151 x 0.5 -> 75 updates.
    assert (result.episodes, result.env_steps, result.updates) == (10, 200, 75)
    table = rows(tmp_path)
    assert [int(r["episode"]) for r in table] == list(range(10))
    assert [int(r["stops"]) for r in table] == [1, 0] * 5
    assert all(int(r["length"]) == EPISODE_STEPS and r["truncated"] == "1" for r in table)
    assert [int(r["env_steps"]) for r in table] == [20 * (i + 1) for i in range(10)]
    policy = QPolicy.load(result.policy_path)
    assert policy.card["episodes"] == 10 and policy.card["env_steps"] == 200
    assert policy.card["config"]["mode"] == "fast"
    assert result.curve_path.stat().st_size > 1000
    ckpt = load_checkpoint(tmp_path / "checkpoints")
    assert ckpt.trainer["episodes_done"] == 10 and ckpt.replay is not None
    assert ckpt.replay["obs"].shape == (200, 8)
    assert (
        json.loads((tmp_path / "checkpoints" / "config.json").read_text())["config"]["mode"]
        == "fast"
    )

    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    events = EventAccumulator(str(tmp_path / "tb"))
    events.Reload()
    tags = set(events.Tags()["scalars"])
    assert {"charts/episodic_return", "charts/epsilon", "losses/td_loss"} <= tags
    assert len(events.Scalars("charts/episodic_return")) == 10
    assert len(events.Scalars("losses/td_loss")) == 7  # updates 10, 20, ..., 70


def test_a_run_is_a_function_of_its_seed(tmp_path: Path) -> None:
    def run(seed: int, out: str) -> tuple[list[dict[str, str]], dict[str, np.ndarray]]:
        train(tiny(episodes=5, seed=seed), tmp_path / out, env_factory=FACTORY)
        table = [{k: v for k, v in r.items() if k != "wall_time_s"} for r in rows(tmp_path / out)]
        net = QPolicy.load(tmp_path / out / "policy.pt").network
        return table, {k: v.numpy() for k, v in net.state_dict().items()}

    (table, weights), (again, same) = run(0, "a"), run(0, "b")
    assert table == again and weights.keys() == same.keys()
    assert all(np.array_equal(weights[k], same[k]) for k in weights)
    other, _ = run(1, "c")
    assert [r["seed"] for r in other] != [r["seed"] for r in table]


def test_resume_continues_where_the_run_stopped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("explaindrive.agent.trainer.git_commit", lambda: "a" * 40)
    train(tiny(episodes=6), tmp_path, env_factory=FACTORY)
    with pytest.raises(CheckpointError, match="already holds a training run"):
        train(tiny(episodes=6), tmp_path, env_factory=FACTORY)
    monkeypatch.setattr("explaindrive.agent.trainer.git_commit", lambda: "b" * 40)
    result = train(tiny(episodes=10), tmp_path, env_factory=FACTORY, resume=True)
    assert (result.episodes, result.env_steps, result.updates) == (10, 200, 75)
    assert [int(r["episode"]) for r in rows(tmp_path)] == list(range(10))
    # the card names the commit the run started from and every commit it was resumed at
    card = QPolicy.load(result.policy_path).card
    assert card["git_commit"] == "a" * 40
    assert card["git_commits"] == ["a" * 40, "b" * 40]


def test_resume_refuses_a_mismatched_or_corrupt_checkpoint(tmp_path: Path) -> None:
    train(tiny(episodes=2), tmp_path, env_factory=FACTORY)
    ckpt = tmp_path / "checkpoints" / "checkpoint.pt"
    with pytest.raises(CheckpointError, match=r"hidden_sizes.*") as err:
        train(tiny(episodes=4, hidden_sizes=[8]), tmp_path, env_factory=FACTORY, resume=True)
    assert str(ckpt) in str(err.value)
    with pytest.raises(CheckpointError, match=r"near_range_m: checkpoint None vs run 10\.0"):
        train(tiny(episodes=4, near_range_m=10.0), tmp_path, env_factory=FACTORY, resume=True)
    ckpt.write_bytes(b"not a checkpoint")
    with pytest.raises(CheckpointError, match="is not an explaindrive checkpoint file") as err:
        train(tiny(episodes=4), tmp_path, env_factory=FACTORY, resume=True)
    assert str(ckpt) in str(err.value)
    with pytest.raises(CheckpointError, match="not found"):
        train(tiny(episodes=4), tmp_path / "empty", env_factory=FACTORY, resume=True)


def test_a_run_stopped_before_its_first_checkpoint_starts_afresh(tmp_path: Path) -> None:
    train(tiny(episodes=3, checkpoint_every_episodes=100), tmp_path, env_factory=FACTORY)
    (tmp_path / "checkpoints" / "checkpoint.pt").unlink()  # as if killed before it was written
    assert len(rows(tmp_path)) == 3
    train(tiny(episodes=5), tmp_path, env_factory=FACTORY)
    assert [int(r["episode"]) for r in rows(tmp_path)] == [0, 1, 2, 3, 4]  # not 3 + 5 rows
    assert "left no checkpoint; this run starts it afresh" in (tmp_path / "train.log").read_text()


def test_subprocess_envs_collect_in_parallel(tmp_path: Path) -> None:
    result = train(
        tiny(episodes=4, num_envs=2, checkpoint_every_episodes=2),
        tmp_path, env_factory=FACTORY, subprocess_envs=True,
    )  # fmt: skip
    # both envs play 20-step episodes in lockstep: 4 episodes = 80 transitions
    assert (result.episodes, result.env_steps) == (4, 80)
    assert sorted(int(r["episode"]) for r in rows(tmp_path)) == [0, 1, 2, 3]
    assert {int(r["env"]) for r in rows(tmp_path)} == {0, 1}


def test_a_run_with_near_range_features_ships_them(tmp_path: Path) -> None:
    train(tiny(episodes=2, near_range_m=10.0), tmp_path, env_factory=FACTORY)
    net = QPolicy.load(tmp_path / "policy.pt").network
    assert net.near_range_m == 10.0 and net.trunk[0].in_features == 11


def test_episodes_that_cannot_start_get_a_new_seed(tmp_path: Path) -> None:
    config = tiny(episodes=8, seed_pool=2)
    bad = SEED_POOL_BASE
    n_bad = sum(plan_episode(config, i).seed == bad for i in range(8))
    assert 0 < n_bad < 8
    factory = functools.partial(FakeDriveEnv, max_steps=EPISODE_STEPS, fail_seeds=(bad,))
    result = train(config, tmp_path, env_factory=factory)
    assert (result.episodes, result.env_steps) == (8, 160)
    card = QPolicy.load(result.policy_path).card
    assert card["reset_failures"] == n_bad
    assert bad not in {int(r["seed"]) for r in rows(tmp_path)}


SCRIPT = """
import functools, sys
sys.path.insert(0, {root!r})
from explaindrive.agent.config import TrainConfig
from explaindrive.agent import trainer as trainer_module
from explaindrive.agent.trainer import train
from tests.agent.fake_drive_env import FakeDriveEnv
config = TrainConfig.from_dict({config!r})
train(config, {out!r}, env_factory=functools.partial(FakeDriveEnv, max_steps=20,
                                                     step_delay_s=0.002))
"""


@pytest.mark.slow
def test_killed_run_resumes_from_its_last_checkpoint(tmp_path: Path) -> None:
    out = tmp_path / "run"
    config = tiny(episodes=100_000)
    root = str(Path(__file__).resolve().parents[2])
    code = textwrap.dedent(SCRIPT).format(root=root, config=config.to_dict(), out=str(out))
    proc = subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE)
    ckpt = out / "checkpoints" / "checkpoint.pt"
    deadline = time.monotonic() + 120
    while not ckpt.exists():
        assert proc.poll() is None, proc.stderr.read().decode() if proc.stderr else ""
        assert time.monotonic() < deadline, "no checkpoint within 120 s"
        time.sleep(0.05)
    time.sleep(0.3)  # let it run past the checkpoint, so some transitions are lost
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()

    saved = load_checkpoint(out / "checkpoints", config).trainer
    done = saved["episodes_done"]
    assert done % 4 == 0 and done >= 4
    assert len(rows(out)) >= done  # rows written after the checkpoint are dropped on resume
    result = train(config.replace(episodes=done + 3), out, env_factory=FACTORY, resume=True)
    assert result.episodes == done + 3
    assert result.env_steps == (done + 3) * EPISODE_STEPS
    assert [int(r["episode"]) for r in rows(out)] == list(range(done + 3))


def test_moving_average_by_hand() -> None:
    assert moving_average([1, 2, 3, 4, 5], 2).tolist() == [1.0, 1.5, 2.5, 3.5, 4.5]
    assert moving_average([1, 2, 3, 4, 5], 3).tolist() == [1.0, 1.5, 2.0, 3.0, 4.0]


def test_n_step_queue_by_hand() -> None:
    q = NStepQueue(3, 0.5)
    obs = [np.full(8, float(i), np.float32) for i in range(6)]
    mask = np.ones(7, bool)

    def push(i: int, reward: float, terminated: bool = False, done: bool = False) -> list:
        return q.push(obs[i], i, reward, mask, obs[i + 1], mask, terminated, done)

    assert push(0, 1.0) == [] and push(1, 2.0) == []
    (t0,) = push(2, 4.0)  # 1 + 0.5 * 2 + 0.25 * 4 = 3, bootstrapped from obs[3] with 0.5^3
    assert (t0[0][0], t0[1], t0[2], t0[3][0], t0[4], t0[5]) == (0.0, 0, 3.0, 3.0, False, 0.125)
    tail = push(3, 8.0, terminated=True, done=True)
    # at the end every queued step leaves: 2 + 2 + 2 = 6 (0.5^3), 4 + 4 = 8 (0.5^2), 8 (0.5)
    assert [(t[1], t[2], t[4], t[5]) for t in tail] == [
        (1, 6.0, True, 0.125), (2, 8.0, True, 0.25), (3, 8.0, True, 0.5),
    ]  # fmt: skip
    assert [t[3][0] for t in tail] == [4.0, 4.0, 4.0]
    (cut,) = push(4, 1.0, terminated=False, done=True)  # truncated: bootstraps, not terminal
    assert (cut[2], cut[4], cut[5]) == (1.0, False, 0.5)


def test_n_step_queue_cut_at_exploration_by_hand() -> None:
    q = NStepQueue(3, 0.5, cut=True)
    obs = [np.full(8, float(i), np.float32) for i in range(6)]
    masks = [np.arange(7) < i + 1 for i in range(6)]  # a different mask for every state

    def push(i: int, reward: float, greedy: bool = True, done: bool = False) -> list:
        return q.push(obs[i], i, reward, masks[i], obs[i + 1], masks[i + 1], False, done,
                      greedy=greedy)  # fmt: skip

    assert push(0, 1.0) == []
    assert push(1, 2.0, greedy=False) == []
    # step 1 explored: step 0's return is r_0 = 1 alone, bootstrapped from obs[1] (0.5^1)
    (t0,) = push(2, 4.0)
    assert (t0.obs[0], t0.action, t0.reward, t0.next_obs[0], t0.discount) == (0, 0, 1.0, 1, 0.5)
    assert not t0.terminated and t0.next_mask.sum() == 2  # obs[1]'s mask
    # step 1's own action may explore: its return runs on, 2 + 0.5 * 4 + 0.25 * 8 = 6
    (t1,) = push(3, 8.0)
    assert (t1.action, t1.reward, t1.next_obs[0], t1.discount) == (1, 6.0, 4, 0.125)
    # at the end step 4 explores: the returns of steps 2 and 3 stop before it (4 + 0.5 * 8
    # and 8, from obs[4]); step 4's own is its reward, from the last state
    tail = push(4, 16.0, greedy=False, done=True)
    assert [(t.action, t.reward, t.next_obs[0], t.discount) for t in tail] == [
        (2, 8.0, 4, 0.25), (3, 8.0, 4, 0.5), (4, 16.0, 5, 0.5),
    ]  # fmt: skip


class NearTheLimit(FakeDriveEnv):
    """Starts every episode at 9 m/s, 1 m/s under the limit."""

    def reset(self, *, seed=None, options=None):  # type: ignore[no-untyped-def]
        _, info = super().reset(seed=seed, options=options)
        self.v = 9.0
        return self._obs(), {**info, "action_mask": runtime_mask(self._obs())}


def test_safe_learning_ends_the_run_once_episodes_run_clean(tmp_path: Path) -> None:
    # the fake road's limit is 10 m/s: a greedy choice above it is one the shield overrides;
    # acting on the bare network (no shielded episodes) at random first, early episodes speed
    config = tiny(episodes=300, stop_when_safe=5, shielded_fraction=0.0, eps_end=0.0,
                  eps_decay_steps=600)  # fmt: skip
    result = train(config, tmp_path, env_factory=functools.partial(NearTheLimit, max_steps=40))
    assert result.stopped_early and result.episodes < 300
    table = rows(tmp_path)
    assert len(table) == result.episodes

    def clean(r: dict[str, str]) -> bool:
        return float(r["shield_share"]) == 0.0 and r["speeding_steps"] == "0"

    assert len(table) > 5 and all(clean(r) for r in table[-5:]) and not clean(table[-6])
    assert all(r["shielded"] == "0" for r in table)
    assert QPolicy.load(result.policy_path).card["stopped_early"] is True


def test_prioritised_replay_trains_and_resumes_with_its_priorities(tmp_path: Path) -> None:
    config = tiny(episodes=6, priority_alpha=0.6, priority_beta_steps=200)
    result = train(config, tmp_path, env_factory=FACTORY)
    assert (result.episodes, result.env_steps, result.updates) == (6, 120, 35)
    replay = load_checkpoint(tmp_path / "checkpoints").replay
    assert replay is not None
    priorities = replay["priorities"]
    assert priorities.shape == (120,) and np.all(priorities > 0.0)
    # updated rows carry (|TD error| + eps)^0.6, the rest the largest priority so far
    assert len(np.unique(priorities)) > 10
    resumed = train(config.replace(episodes=10), tmp_path, env_factory=FACTORY, resume=True)
    assert (resumed.episodes, resumed.env_steps, resumed.updates) == (10, 200, 75)


def test_boundary_states_join_the_updates(tmp_path: Path) -> None:
    result = train(tiny(episodes=4, boundary_weight=1.0), tmp_path, env_factory=FACTORY)
    assert (result.episodes, result.updates) == (4, 15)
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    events = EventAccumulator(str(tmp_path / "tb"))
    events.Reload()
    losses = [e.value for e in events.Scalars("losses/boundary_loss")]
    assert len(losses) == 1 and losses[0] >= 0.0  # logged at update 10


@pytest.mark.parametrize("boundary_noise", [False, True])
def test_boundary_rows_are_seen_through_noise_when_asked(
    boundary_noise: bool, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen: list[tuple[object, ...]] = []
    real = trainer_module.boundary_batch

    def spy(*args: object, **kwargs: object) -> object:
        seen.append(args[3:])
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(trainer_module, "boundary_batch", spy)
    config = tiny(episodes=4, boundary_weight=1.0, obs_noise_max=[2.0, 0.6], noisy_share=0.5,
                  boundary_noise=boundary_noise)  # fmt: skip
    train(config, tmp_path, env_factory=FACTORY)
    expected = ((2.0, 0.6) if boundary_noise else (0.0, 0.0), 0.5)
    assert seen and all(args == expected for args in seen)
