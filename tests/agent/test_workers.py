"""Rollout workers and their local pools."""

from __future__ import annotations

import functools
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch

from explaindrive.agent.config import preset
from explaindrive.agent.estimator import SpeedEstimator
from explaindrive.agent.network import DuelingQNetwork
from explaindrive.agent.rollout import CollectRequest, RolloutWorker
from explaindrive.agent.schedule import plan_episode
from explaindrive.agent.workers import InProcessPool, ProcessPool, make_pool
from explaindrive.env.actions import limited_change, speed_change
from tests.agent.fake_drive_env import FakeDriveEnv

CONFIG = preset("safe").replace(hidden_sizes=[8], n_step=3, num_envs=2, episodes=10)
FACTORY = functools.partial(FakeDriveEnv, max_steps=5)


def _broken_env() -> FakeDriveEnv:
    raise OSError("no SUMO here")


def _weights() -> dict[str, torch.Tensor]:
    torch.manual_seed(0)
    return DuelingQNetwork((8,)).state_dict()


def test_a_worker_plays_its_reserved_episode_and_ships_n_step_transitions() -> None:
    worker = RolloutWorker(CONFIG, FACTORY, 0)
    first = worker.collect(CollectRequest(steps=3, epsilon=0.5, weights=_weights(), start=4))
    assert (first.steps, first.started, first.running, first.episodes) == (3, True, 4, [])
    assert len(first.transitions) == 1  # 3 steps complete one 3-step transition
    # two more steps end the 5-step episode; no new one is reserved, so the round stops
    second = worker.collect(CollectRequest(steps=10, epsilon=0.5))
    assert (second.steps, second.started, second.running) == (2, False, None)
    assert len(second.transitions) == 4  # the episode's remaining 4 transitions
    (episode,) = second.episodes
    assert (episode.index, episode.length, episode.ended_at_step) == (4, 5, 2)
    assert not episode.terminated  # the fake road truncates at 5 steps
    *_, terminated, discount, mask, next_mask = second.transitions[-1]
    assert discount == pytest.approx(CONFIG.gamma) and not terminated
    assert mask.shape == next_mask.shape == (7,)
    idle = worker.collect(CollectRequest(steps=10, epsilon=0.5))
    assert (idle.steps, idle.transitions) == (0, [])


@pytest.mark.parametrize(("epsilon", "full_returns"), [(0.0, 2), (1.0, 0)])
def test_cut_returns_stop_at_exploration_and_keep_the_random_stream(
    epsilon: float, full_returns: int
) -> None:
    # 4 steps of a 5-step episode: two transitions leave, each spanning 3 steps when every
    # action is the network's best; with every action random (epsilon 1) the second step
    # of each return explores (on 4 steps of this seed), so each stops after one step
    plain, cut = (RolloutWorker(CONFIG.replace(n_step_cut=c), FACTORY, 0) for c in (False, True))
    a, b = (w.collect(CollectRequest(4, epsilon, _weights(), start=4)) for w in (plain, cut))
    assert [t.action for t in a.transitions] == [t.action for t in b.transitions]
    discounts = [t.discount for t in b.transitions]
    assert len(discounts) == 2
    assert discounts.count(pytest.approx(CONFIG.gamma**3)) == full_returns
    assert discounts.count(pytest.approx(CONFIG.gamma)) == 2 - full_returns


def test_local_processes_play_exactly_what_in_process_workers_play() -> None:
    requests = [CollectRequest(7, 0.3, _weights(), start) for start in (0, 1)]
    results = []
    for pool in (InProcessPool(CONFIG, FACTORY, 2), ProcessPool(CONFIG, FACTORY, 2)):
        try:
            pool.submit(requests)
            results.append(pool.gather())
        finally:
            pool.close()
    for a, b in zip(*results, strict=True):
        assert (a.steps, a.running) == (b.steps, b.running)
        assert [ep.ret for ep in a.episodes] == [ep.ret for ep in b.episodes]
        for ta, tb in zip(a.transitions, b.transitions, strict=True):
            assert all(np.array_equal(x, y) for x, y in zip(ta, tb, strict=True))


def test_worker_errors_name_the_worker() -> None:
    with pytest.raises(RuntimeError, match=r"env worker 0 failed:[\s\S]*no SUMO here"):
        ProcessPool(CONFIG, _broken_env, 1)
    with pytest.raises(ValueError, match="num_workers must be > 0"):
        make_pool(CONFIG, FACTORY, 0)
    assert isinstance(make_pool(CONFIG, FACTORY, 1), InProcessPool)


class _YellowAhead(FakeDriveEnv):
    """Always a yellow light 17.9 m ahead at 13 m/s: the dilemma zone (braking hardest
    covers 10 + 7 + 4 + 1 = 22 m)."""

    def _obs(self) -> np.ndarray:
        return np.array([0, 13.0, 13.9, 17.9, 13.0, 17.9, 1.0, 200.0], dtype=np.float32)


@pytest.mark.parametrize(("dilemma_braking", "allowed"), [(True, 4), (False, 1)])
def test_the_learning_mask_follows_the_dilemma_braking_setting(
    dilemma_braking: bool, allowed: int
) -> None:
    config = CONFIG.replace(dilemma_braking=dilemma_braking)
    worker = RolloutWorker(config, functools.partial(_YellowAhead, max_steps=5), 0)
    rollout = worker.collect(CollectRequest(steps=5, epsilon=0.5, weights=_weights(), start=0))
    assert rollout.transitions
    for *_, mask, next_mask in rollout.transitions:
        # -3..0 m/s when braking is left to the rewards; keeping the speed only otherwise
        assert mask.sum() == next_mask.sum() == allowed and mask[3]


class _NoisySensor(FakeDriveEnv):
    """Sees an empty road while the true state (``info["true_obs"]``) is _YellowAhead's."""

    true = np.array([0, 13.0, 13.9, 17.9, 13.0, 17.9, 1.0, 200.0], dtype=np.float32)

    def _true_obs(self) -> np.ndarray:
        return self.true

    def reset(self, *, seed=None, options=None):  # type: ignore[no-untyped-def]
        obs, info = super().reset(seed=seed, options=options)
        return obs, {**info, "true_obs": self.true}

    def step(self, action: int):  # type: ignore[no-untyped-def]
        obs, reward, terminated, truncated, info = super().step(action)
        return obs, reward, terminated, truncated, {**info, "true_obs": self.true}


def test_the_learning_mask_is_computed_on_the_true_state() -> None:
    worker = RolloutWorker(CONFIG, functools.partial(_NoisySensor, max_steps=5), 0)
    rollout = worker.collect(CollectRequest(steps=5, epsilon=0.5, weights=_weights(), start=0))
    for obs, *_, mask, next_mask in rollout.transitions:
        assert obs[5] == 200.0  # the network learns from what it sees...
        assert mask.sum() == next_mask.sum() == 4  # ...and the masks from the true state


class _NoisySpeedometer(FakeDriveEnv):
    """Starts at rest and reads its speed through noise of 0.5 m/s; keeps the readings."""

    def reset(self, *, seed=None, options=None):  # type: ignore[no-untyped-def]
        _, info = super().reset(seed=seed, options=options)
        self.v, self.readings = 0.0, []
        return self._read(self._obs()), {**info, "true_obs": self._obs()}

    def step(self, action: int):  # type: ignore[no-untyped-def]
        obs, reward, terminated, truncated, info = super().step(action)
        return self._read(obs), reward, terminated, truncated, {**info, "true_obs": obs}

    def _read(self, obs: np.ndarray) -> np.ndarray:
        seen = obs.copy()
        seen[1] = max(0.0, obs[1] + 0.5 * self.np_random.standard_normal())
        self.readings.append(float(seen[1]))
        return seen


def test_with_speed_estimate_the_network_learns_from_the_controller_s_estimate() -> None:
    config = CONFIG.replace(speed_estimate=True, obs_noise_max=(0.0, 0.9), noisy_share=1.0)
    sd = plan_episode(config, 0).obs_noise[1]
    assert sd > 0.0
    worker = RolloutWorker(config, functools.partial(_NoisySpeedometer, max_steps=5), 0)
    rollout = worker.collect(CollectRequest(steps=5, epsilon=0.5, weights=_weights(), start=0))
    est, change, expected = SpeedEstimator(sd), None, []
    for reading, transition in zip(worker.env.readings, rollout.transitions, strict=False):
        expected.append(est.update(reading, change))
        change = speed_change(transition.action)
    assert len(expected) == 5 and expected[0] == 0.0
    assert [float(t.obs[1]) for t in rollout.transitions] == pytest.approx(expected, abs=1e-6)
    assert [float(t.obs[1]) for t in rollout.transitions] != pytest.approx(
        worker.env.readings[:5], abs=1e-3
    )


class _LimitedSpeedometer(_NoisySpeedometer):
    """The same under a 1.5 m/s limit with the speed limiter: a rise past it lands on it."""

    def _obs(self) -> np.ndarray:
        obs = super()._obs()
        obs[2] = 1.5
        return obs

    def step(self, action: int):  # type: ignore[no-untyped-def]
        v = self.v
        _, reward, terminated, truncated, info = FakeDriveEnv.step(self, action)
        self.v = max(0.0, v + limited_change(v, speed_change(int(action)), 1.5))
        obs = self._obs()
        return self._read(obs), reward, terminated, truncated, {**info, "true_obs": obs}


def test_under_the_speed_limiter_the_estimate_predicts_the_change_it_let_through() -> None:
    config = CONFIG.replace(
        speed_estimate=True, obs_noise_max=(0.0, 0.9), noisy_share=1.0, speed_limiter=True
    )
    sd = plan_episode(config, 0).obs_noise[1]
    worker = RolloutWorker(config, functools.partial(_LimitedSpeedometer, max_steps=5), 0)
    rollout = worker.collect(CollectRequest(steps=5, epsilon=1.0, weights=_weights(), start=0))
    est, change, expected = SpeedEstimator(sd), None, []
    for reading, transition in zip(worker.env.readings, rollout.transitions, strict=False):
        expected.append(est.update(reading, change))
        change = limited_change(expected[-1], speed_change(transition.action), 1.5)
    seen = [float(t.obs[1]) for t in rollout.transitions]
    assert seen == pytest.approx(expected, abs=1e-6)
    assert max(seen) < 1.5 + 0.5  # the limiter holds the car at 1.5; the estimate follows


_KILLED_PARENT = """
import functools, os, signal, sys
sys.path.insert(0, {root!r})
from explaindrive.agent.config import preset
from explaindrive.agent.rollout import CollectRequest
from explaindrive.agent.workers import ProcessPool
from tests.agent.fake_drive_env import FakeDriveEnv

if __name__ == "__main__":
    config = preset("safe").replace(hidden_sizes=[8], num_envs=2, episodes=10)
    factory = functools.partial(FakeDriveEnv, max_steps=100_000, step_delay_s=0.01)
    pool = ProcessPool(config, factory, 2)
    pool.submit([CollectRequest(100_000, 0.5, None, start) for start in (0, 1)])
    print(*(proc.pid for proc in pool._procs), flush=True)  # a 1,000 s round each
    os.kill(os.getpid(), signal.SIGKILL)
"""


def _running(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has ended
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="parent-death signal: Linux")
def test_workers_end_with_a_killed_parent(tmp_path: Path) -> None:
    root = str(Path(__file__).resolve().parents[2])
    script = tmp_path / "parent.py"
    script.write_text(_KILLED_PARENT.format(root=root), encoding="utf-8")
    # the workers inherit the pipe, so read the line and wait for the parent alone
    with subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                          text=True, cwd=root) as parent:  # fmt: skip
        assert parent.stdout is not None
        pids = [int(p) for p in parent.stdout.readline().split()]
        assert parent.wait(timeout=60) == -signal.SIGKILL
        assert len(pids) == 2
        parent.stdout.close()
    deadline = time.monotonic() + 10.0
    while any(map(_running, pids)) and time.monotonic() < deadline:
        time.sleep(0.1)
    alive = [pid for pid in pids if _running(pid)]
    for pid in alive:
        os.kill(pid, signal.SIGKILL)
    assert not alive, "rollout workers outlived their killed parent"


@pytest.mark.parametrize(("name", "rule"), [("paper", "always"), ("safe", "decided")])
def test_the_real_env_factory_builds_the_presets_yellow_rule(name: str, rule: str) -> None:
    from explaindrive.agent.rollout import default_env_factory

    env = default_env_factory(preset(name).replace(max_episode_steps=50))()
    try:
        assert (env.config.yellow_leader, env.config.max_steps) == (rule, 50)  # type: ignore[attr-defined]
    finally:
        env.close()


def test_the_real_env_factory_passes_the_stop_window_to_the_reward() -> None:
    from explaindrive.agent.rollout import default_env_factory

    config = preset("passenger", "comfort").replace(max_episode_steps=50, stop_window_m=(1, 4))
    env = default_env_factory(config)()
    try:
        assert env.recipe.comfort.stop_window_m == (1.0, 4.0)  # type: ignore[attr-defined]
        assert env.recipe.comfort.cruise == 5.0  # type: ignore[attr-defined]
    finally:
        env.close()
