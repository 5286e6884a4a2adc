"""Rollout workers: each plays its own episodes with a copy of the Q-network.

A worker owns one environment (libsumo runs one simulation per process) and a copy of the
learner's network, refreshed when the learner sends new weights. Each
:meth:`RolloutWorker.collect` plays up to ``steps`` environment steps: epsilon-greedy
actions (through the safety mask in shielded episodes), the safety masks of every state, n-step
transitions, and a summary of every episode that ended; the whole batch goes back to the
learner at once. When an episode ends the worker starts the one the learner reserved for it
(:attr:`CollectRequest.start`); without one it stops early.

Everything a worker does is a function of the request, the weights and the episode's plan
(the exploration RNG is seeded per episode), so a run does not depend on timing.
"""

from __future__ import annotations

import functools
import logging
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import gymnasium as gym
import numpy as np
import torch

from explaindrive.agent.buffer import Transition
from explaindrive.agent.config import TrainConfig
from explaindrive.agent.estimator import SpeedEstimator, commanded_change
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.network import DuelingQNetwork
from explaindrive.agent.schedule import EpisodePlan, plan_episode
from explaindrive.agent.shield import limit_mask, training_mask
from explaindrive.env.lights import DEFAULT_YELLOW_LEADER
from explaindrive.env.state import V_EGO, V_LIM
from explaindrive.sim.scenario.layout import SEED_LIMIT

log = logging.getLogger(__name__)

EnvFactory = Callable[[], gym.Env]
"""Builds one environment; must be picklable (a module-level function or a partial)."""

SAFETY_FLAGS: tuple[str, ...] = ("collision", "red_light_run", "ped_violation", "yield_violation")
MAX_RESET_ATTEMPTS = 5


def reseed(seed: int, attempt: int) -> int:
    """Replacement seed for an episode whose env could not start with ``seed``."""
    return int(np.random.default_rng([seed, attempt, 7]).integers(0, SEED_LIMIT - 1))


def make_urban_drive_env(
    max_steps: int | None = None,
    yellow_leader: str = DEFAULT_YELLOW_LEADER,
    scenario: Mapping[str, Any] | None = None,
    reward: str = "paper",
    stop_window_m: tuple[float, float] | None = None,
    speed_limiter: bool = False,
) -> gym.Env:
    """The project's SUMO environment (imported lazily: each worker builds its own) in the
    ``scenario`` chosen by these env config fields (the paper's road by default)."""
    from explaindrive.env.config import EnvConfig
    from explaindrive.env.urban_drive import UrbanDriveEnv

    config = EnvConfig(
        yellow_leader=yellow_leader,
        reward=reward,
        stop_window_m=stop_window_m,
        speed_limiter=speed_limiter,
        **dict(scenario or {}),
    )
    return UrbanDriveEnv(
        config=config if max_steps is None else config.replace(max_steps=max_steps)
    )


def default_env_factory(config: TrainConfig) -> EnvFactory:
    """Picklable factory of the real environment for ``config``."""
    return functools.partial(
        make_urban_drive_env,
        config.max_episode_steps,
        config.yellow_leader,
        config.scenario_fields(),
        config.reward,
        config.stop_window_m,
        config.speed_limiter,
    )


def _true_state(obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
    """The true state behind an observation: the masks of learning are computed on it, so a
    network that sees noisy observations learns the margin the noise calls for."""
    true = info.get("true_obs")
    return obs if true is None else np.asarray(true, dtype=np.float32)


def _allowed(info: dict[str, Any]) -> np.ndarray:
    """The actions the run-time shield keeps in the true state: the env's
    ``info["action_mask"]`` (:func:`~explaindrive.env.safety.runtime_mask` of it)."""
    return np.asarray(info["action_mask"], dtype=bool)


def learning_mask(
    seen: np.ndarray, true: np.ndarray, dilemma_braking: bool, speed_limiter: bool = False
) -> np.ndarray:
    """The safe actions learning uses: the training mask of the true state and, when the
    network sees a noisy speed, the posted-limit rule on what it sees as well (a car that
    sees itself over the limit slows down, which keeps a margin below the limit under
    noise). If the two leave nothing, the true state's mask alone. ``speed_limiter``: both
    through the speed limiter."""
    mask = training_mask(true, dilemma_braking, speed_limiter)
    if seen is true:
        return mask
    both = mask & limit_mask(seen, speed_limiter)
    return both if both.any() else mask


class NStepQueue:
    """Turns the steps of one episode into n-step transitions.

    A transition leaves the queue when n steps have followed its state (return
    r_0 + g r_1 + ... + g^(n-1) r_(n-1), bootstrapped from the state n steps later with
    discount g^n), or when the episode ends (the shorter tail returns, each marked
    terminated if the episode terminated). With ``cut``, a return stops before the first
    later step whose action was exploratory (``greedy=False``) and bootstraps from that
    step's state.
    """

    def __init__(self, n: int, gamma: float, cut: bool = False) -> None:
        self.n, self.gamma, self.cut = n, gamma, cut
        self._steps: deque[tuple[np.ndarray, int, float, np.ndarray, bool]] = deque()

    def push(
        self,
        obs: np.ndarray,
        action: int,
        reward: float,
        mask: np.ndarray,
        next_obs: np.ndarray,
        next_mask: np.ndarray,
        terminated: bool,
        done: bool,
        greedy: bool = True,
    ) -> list[Transition]:
        """Add one step; returns the transitions it completes."""
        self._steps.append((obs, action, reward, mask, greedy))
        out: list[Transition] = []
        while self._steps and (done or len(self._steps) >= self.n):
            span = self._span()
            ret = sum(self.gamma**k * self._steps[k][2] for k in range(span))
            first_obs, first_action, _, first_mask, _ = self._steps.popleft()
            discount = self.gamma**span
            if span <= len(self._steps):  # cut: bootstrap from the exploratory step's state
                cut_obs, _, _, cut_mask, _ = self._steps[span - 1]
                out.append(Transition(first_obs, first_action, ret, cut_obs, False, discount,
                                      first_mask, cut_mask))  # fmt: skip
            else:
                out.append(Transition(first_obs, first_action, ret, next_obs,
                                      terminated and done, discount, first_mask,
                                      next_mask))  # fmt: skip
        return out

    def _span(self) -> int:
        """Steps the first queued step's return sums: all queued ones, or with ``cut`` those
        before the first later exploratory step."""
        if self.cut:
            for k in range(1, len(self._steps)):
                if not self._steps[k][4]:
                    return k
        return len(self._steps)


@dataclass(frozen=True)
class CollectRequest:
    """What the learner asks of a worker for one round."""

    steps: int
    epsilon: float
    weights: dict[str, Any] | None = None  # new network weights; None keeps the current ones
    start: int | None = None  # the episode to start when none is running (or the current ends)


@dataclass
class EpisodeSummary:
    """Figures of one finished episode (a row of ``episodes.csv`` without the learner's)."""

    index: int
    seed: int
    traffic_level: float
    stops: bool
    shielded: bool
    ret: float = 0.0
    length: int = 0
    speed_sum: float = 0.0
    speeding_steps: int = 0
    greedy_unsafe: int = 0
    flags: dict[str, bool] = field(default_factory=lambda: dict.fromkeys(SAFETY_FLAGS, False))
    distance_m: float = 0.0
    terminated: bool = False
    ended_at_step: int = 0  # steps the worker had played in its round when the episode ended

    def record(self, reward: float, info: dict[str, Any], greedy_unsafe: bool) -> None:
        """Add one step."""
        self.ret += reward
        self.length += 1
        self.speed_sum += float(info.get("speed_mps", 0.0))
        self.speeding_steps += int(bool(info.get("speeding", False)))
        self.greedy_unsafe += int(greedy_unsafe)
        for key in SAFETY_FLAGS:
            self.flags[key] = self.flags[key] or bool(info.get(key, False))
        self.distance_m = float(info.get("distance_m", self.distance_m))

    @property
    def clean(self) -> bool:
        """No greedy action needed overriding and nothing was violated."""
        return not self.greedy_unsafe and not self.speeding_steps and not any(self.flags.values())

    @property
    def shield_share(self) -> float:
        """Share of the steps whose greedy action the shield would have replaced."""
        return self.greedy_unsafe / max(self.length, 1)

    @property
    def mean_speed_mps(self) -> float:
        """Mean ego speed over the episode [m/s]."""
        return self.speed_sum / max(self.length, 1)


@dataclass
class Rollout:
    """What a worker played in one round."""

    transitions: list[Transition]
    episodes: list[EpisodeSummary]
    steps: int
    started: bool  # whether the reserved episode was started
    running: int | None  # the episode under way at the end of the round
    reset_failures: int = 0


@dataclass
class _Running:
    plan: EpisodePlan
    summary: EpisodeSummary
    queue: NStepQueue
    rng: np.random.Generator
    obs: np.ndarray
    mask: np.ndarray  # the safe actions of obs for learning (training_mask)
    allowed: np.ndarray  # the actions the run-time shield keeps in obs
    estimator: SpeedEstimator | None  # the speed seen is the estimate (``speed_estimate``)


class RolloutWorker:
    """One environment and a copy of the network; see the module docstring.

    Args:
        config: the run's config.
        env_factory: builds the environment.
        worker_id: this worker's index (names it in logs).
    """

    def __init__(self, config: TrainConfig, env_factory: EnvFactory, worker_id: int) -> None:
        torch.set_num_threads(1)
        self.config = config
        self.worker_id = worker_id
        self.env = env_factory()
        self.net = DuelingQNetwork(config.hidden_sizes, near_range_m=config.near_range_m)
        self.net.requires_grad_(False)
        self.episode: _Running | None = None

    def collect(self, request: CollectRequest) -> Rollout:
        """Play up to ``request.steps`` steps; see the module docstring."""
        if request.weights is not None:
            self.net.load_state_dict(request.weights)
        out = Rollout([], [], 0, False, None)
        start = request.start
        while out.steps < request.steps:
            if self.episode is None:
                if start is None:
                    break
                self.episode = self._start(plan_episode(self.config, start), out)
                start, out.started = None, True
            self._step(self.episode, request.epsilon, out)
        out.running = self.episode.plan.index if self.episode is not None else None
        return out

    def drop_episode(self) -> None:
        """Forget the episode under way (the learner restarts it elsewhere)."""
        self.episode = None

    def close(self) -> None:
        """Release the environment."""
        self.env.close()

    def _start(self, plan: EpisodePlan, out: Rollout) -> _Running:
        c = self.config
        for attempt in range(MAX_RESET_ATTEMPTS):
            try:
                obs, info = self.env.reset(seed=plan.seed, options=plan.reset_options())
            except (RuntimeError, OSError) as exc:  # e.g. the ego cannot enter a blocked road
                out.reset_failures += 1
                log.warning("episode %d (seed %d) could not start: %s; new seed",
                            plan.index, plan.seed, exc)  # fmt: skip
                plan = replace(plan, seed=reseed(plan.seed, attempt))
                continue
            obs = np.asarray(obs, dtype=np.float32)
            true_obs = _true_state(obs, info)
            estimator = SpeedEstimator(plan.obs_noise[1]) if c.speed_estimate else None
            if estimator is not None:
                obs[V_EGO] = estimator.update(float(obs[V_EGO]), None)
            shielded = c.safe_learning and plan.index < c.shielded_fraction * c.episodes
            summary = EpisodeSummary(
                plan.index, plan.seed, plan.traffic_level, plan.has_stops, shielded
            )
            return _Running(
                plan, summary, NStepQueue(c.n_step, c.gamma, c.n_step_cut),
                np.random.default_rng([c.seed, 3, plan.index]), obs,
                learning_mask(obs, true_obs, c.dilemma_braking, c.speed_limiter),
                _allowed(info), estimator,
            )  # fmt: skip
        raise RuntimeError(
            f"worker {self.worker_id}: episode {plan.index} failed to start "
            f"{MAX_RESET_ATTEMPTS} times"
        )

    def _step(self, ep: _Running, epsilon: float, out: Rollout) -> None:
        with torch.no_grad():
            q = self.net(torch.from_numpy(ep.obs[None])).numpy()
        greedy_unsafe = not ep.allowed[int(q[0].argmax())]
        act_mask = ep.mask[None] if ep.summary.shielded else None
        action = int(D3QNLearner.explore(q, epsilon, ep.rng, act_mask)[0])
        # only the cut returns ask whether the action was the network's (allowed) best
        greedy = not self.config.n_step_cut or action == int(
            D3QNLearner.best_actions(q, act_mask)[0]
        )
        next_obs, reward, terminated, truncated, info = self.env.step(action)
        next_obs = np.asarray(next_obs, dtype=np.float32)
        next_true = _true_state(next_obs, info)
        if ep.estimator is not None:
            change = commanded_change(
                float(ep.obs[V_EGO]), action, float(ep.obs[V_LIM]), self.config.speed_limiter
            )
            next_obs[V_EGO] = ep.estimator.update(float(next_obs[V_EGO]), change)
        next_mask = learning_mask(
            next_obs, next_true, self.config.dilemma_braking, self.config.speed_limiter
        )
        done = bool(terminated or truncated)
        out.transitions += ep.queue.push(
            ep.obs, action, float(reward), ep.mask, next_obs, next_mask, bool(terminated), done,
            greedy=greedy,
        )  # fmt: skip
        out.steps += 1
        ep.summary.record(float(reward), info, greedy_unsafe)
        ep.obs, ep.mask, ep.allowed = next_obs, next_mask, _allowed(info)
        if done:
            ep.summary.terminated = bool(terminated)
            ep.summary.ended_at_step = out.steps
            out.episodes.append(ep.summary)
            self.episode = None
