"""The training loop: parallel collection, D3QN updates, logs, checkpoints and resume.

Outputs of a run directory ``out``:

- ``episodes.csv``: one row per finished episode (return, length, safety flags, speed, the
  share of steps whose greedy action the shield would override...);
- ``tb/``: TensorBoard scalars (``charts/episodic_return``, ``charts/epsilon``,
  ``charts/steps_per_second``, ``losses/td_loss``, ``losses/q_values``...), x = env steps;
- ``checkpoints/``: the last checkpoint (see :mod:`explaindrive.agent.checkpoint`);
- ``policy.pt`` + ``policy.json``: the final greedy policy and its card;
- ``training_curve.png``: episode reward with its moving average (the paper's figure).

The loop is pipelined but deterministic: while the workers simulate a step, the learner
makes the updates owed for the transitions already stored, and a finished env resets while
the others step; no decision depends on timing, so a run and its resumed copy are equal.

Resume: the checkpoint holds the networks, the optimiser, the replay buffer, the counters,
the RNG state and the episodes that were running; ``resume=True`` reloads it, truncates
the CSV to the episodes it had logged, and starts the interrupted episodes again with their
original plans. Only the transitions collected after the checkpoint are lost.
"""

from __future__ import annotations

import csv
import functools
import logging
import subprocess
import time
from collections import deque
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch

from explaindrive.agent.buffer import ReplayBuffer
from explaindrive.agent.checkpoint import (
    CHECKPOINT_FILE,
    CheckpointError,
    atomic_write_text,
    load_checkpoint,
    save_checkpoint,
    save_policy,
)
from explaindrive.agent.config import TrainConfig
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.schedule import EpisodePlan, plan_episode
from explaindrive.agent.shield import runtime_mask, training_mask
from explaindrive.agent.vec_env import RESET_FAILED, EnvFactory, VecEnv, make_vec_env
from explaindrive.env.actions import N_ACTIONS

log = logging.getLogger(__name__)

CSV_FIELDS: tuple[str, ...] = (
    "episode", "env", "seed", "traffic_level", "stops", "return", "length", "env_steps",
    "epsilon", "collision", "red_light_run", "ped_violation", "speeding_steps",
    "shield_share", "shielded", "mean_speed_mps", "distance_m", "terminated", "truncated",
    "wall_time_s",
)  # fmt: skip
SAFETY_FLAGS: tuple[str, ...] = ("collision", "red_light_run", "ped_violation")
INFO_KEYS: tuple[str, ...] = ("speed_mps", "speeding", "distance_m", *SAFETY_FLAGS)
"""The info keys the trainer reads; the env workers send only these."""
MAX_RESET_ATTEMPTS = 5


def reseed(seed: int, attempt: int) -> int:
    """Replacement seed for an episode whose env could not start with ``seed``."""
    return int(np.random.default_rng([seed, attempt, 7]).integers(0, 2**31 - 1))


def make_urban_drive_env(max_steps: int | None = None) -> gym.Env:
    """The project's SUMO environment (imported lazily: each worker builds its own)."""
    from explaindrive.env.config import EnvConfig
    from explaindrive.env.urban_drive import UrbanDriveEnv

    env_config = EnvConfig() if max_steps is None else EnvConfig(max_steps=max_steps)
    return UrbanDriveEnv(config=env_config)


def default_env_factory(config: TrainConfig) -> EnvFactory:
    """Picklable factory of the real environment for ``config``."""
    return functools.partial(make_urban_drive_env, config.max_episode_steps)


Transition = tuple[np.ndarray, int, float, np.ndarray, bool, float, np.ndarray, np.ndarray]
"""(obs, action, return, next_obs, terminated, discount, mask, next_mask)"""


class NStepQueue:
    """Turns the steps of one episode into n-step transitions.

    A transition leaves the queue when n steps have followed its state (return
    r_0 + g r_1 + ... + g^(n-1) r_(n-1), bootstrapped from the state n steps later with
    discount g^n), or when the episode ends (the shorter tail returns, each marked
    terminated if the episode terminated).
    """

    def __init__(self, n: int, gamma: float) -> None:
        self.n, self.gamma = n, gamma
        self._steps: deque[tuple[np.ndarray, int, float, np.ndarray]] = deque()

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
    ) -> list[Transition]:
        """Add one step; returns the transitions it completes."""
        self._steps.append((obs, action, reward, mask))
        out: list[Transition] = []
        while self._steps and (done or len(self._steps) >= self.n):
            ret = sum(self.gamma**k * step[2] for k, step in enumerate(self._steps))
            first_obs, first_action, _, first_mask = self._steps.popleft()
            discount = self.gamma ** (len(self._steps) + 1)
            out.append((first_obs, first_action, ret, next_obs, terminated and done, discount,
                        first_mask, next_mask))  # fmt: skip
        return out


@dataclass
class _Episode:
    """Running statistics of the episode an env is playing."""

    plan: EpisodePlan
    shielded: bool
    queue: NStepQueue
    ret: float = 0.0
    length: int = 0
    speed_sum: float = 0.0
    speeding_steps: int = 0
    greedy_unsafe: int = 0
    flags: dict[str, bool] = field(default_factory=lambda: dict.fromkeys(SAFETY_FLAGS, False))
    distance_m: float = 0.0

    def record(self, reward: float, info: dict[str, Any], greedy_unsafe: bool) -> None:
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


@dataclass
class TrainResult:
    """Summary of a finished run."""

    out_dir: Path
    episodes: int
    env_steps: int
    updates: int
    wall_time_s: float
    steps_per_s: float
    policy_path: Path
    curve_path: Path
    stopped_early: bool = False


def moving_average(values: np.ndarray, window: int) -> np.ndarray:
    """Trailing moving average; the first ``window - 1`` points average what exists so far."""
    values = np.asarray(values, dtype=np.float64)
    if window <= 0:
        raise ValueError(f"window must be > 0, got {window}")
    csum = np.cumsum(np.insert(values, 0, 0.0))
    idx = np.arange(1, len(values) + 1)
    lo = np.maximum(idx - window, 0)
    return (csum[idx] - csum[lo]) / (idx - lo)


def plot_training_curve(csv_path: Path, png_path: Path, window: int = 50, title: str = "") -> Path:
    """The paper's training-curve figure: episode reward and its ``window``-episode average."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with csv_path.open(newline="") as f:
        returns = np.array([float(row["return"]) for row in csv.DictReader(f)])
    fig, ax = plt.subplots(figsize=(7, 4))
    x = np.arange(1, len(returns) + 1)
    ax.plot(x, returns, color="tab:blue", alpha=0.3, linewidth=0.8, label="episode reward")
    if len(returns):
        ax.plot(
            x, moving_average(returns, window), color="tab:blue", label=f"{window}-episode mean"
        )
    ax.set_xlabel("episode")
    ax.set_ylabel("total reward")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    png_path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png_path, dpi=120)
    plt.close(fig)
    return png_path


def git_commit() -> str | None:
    """Commit of the source tree, if it is a git checkout."""
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"],
            cwd=Path(__file__).resolve().parent,
            capture_output=True,
            text=True,
            timeout=5,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None


class _Progress:
    """Rich progress bar (or nothing) showing episode, reward, epsilon and steps/s."""

    def __init__(self, enabled: bool, total: int, done: int, title: str) -> None:
        self._progress = None
        if not enabled:
            return
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
        )

        self._progress = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("reward {task.fields[reward]:>8.1f} (avg {task.fields[avg]:>8.1f})"),
            TextColumn("eps {task.fields[eps]:.3f}"),
            TextColumn("{task.fields[sps]:>6.0f} steps/s"),
            TimeElapsedColumn(),
        )
        self._task = self._progress.add_task(
            title, total=total, completed=done, reward=0.0, avg=0.0, eps=1.0, sps=0.0
        )
        self._progress.start()

    def update(self, done: int, reward: float, avg: float, eps: float, sps: float) -> None:
        if self._progress is not None:
            self._progress.update(
                self._task, completed=done, reward=reward, avg=avg, eps=eps, sps=sps
            )

    def close(self) -> None:
        if self._progress is not None:
            self._progress.stop()


class Trainer:
    """Trains one D3QN agent; see the module docstring for outputs and resume.

    Args:
        config: the run's config.
        out_dir: where every output goes.
        env_factory: builds one env (picklable); defaults to the project's SUMO env.
        resume: continue from ``out_dir/checkpoints``.
        show_progress: draw a rich progress bar.
        subprocess_envs: force (True) or forbid (False) worker processes; by default
            they are used when ``config.envs > 1``.

    Raises:
        CheckpointError: if ``resume`` finds no usable checkpoint, or if ``out_dir``
            already holds a run and ``resume`` is false.
    """

    def __init__(
        self,
        config: TrainConfig,
        out_dir: Path,
        env_factory: EnvFactory | None = None,
        resume: bool = False,
        show_progress: bool = True,
        subprocess_envs: bool | None = None,
    ) -> None:
        self.config = config
        self.out_dir = Path(out_dir)
        self.ckpt_dir = self.out_dir / "checkpoints"
        self.csv_path = self.out_dir / "episodes.csv"
        self.env_factory = env_factory or default_env_factory(config)
        self.show_progress = show_progress
        self.subprocess_envs = subprocess_envs
        torch.set_num_threads(config.torch_threads)

        self.learner = D3QNLearner(config)
        self.buffer = ReplayBuffer(config.buffer_size)
        self.rng = np.random.default_rng([config.seed, 1])
        self.env_steps = 0
        self.episodes_done = 0
        self.next_episode = 0
        self.pending: deque[int] = deque()
        self.update_debt = 0.0
        self.wall_time_s = 0.0
        self.reset_failures = 0
        self.clean_streak = 0  # consecutive finished episodes without override or violation
        self.recent_returns: deque[float] = deque(maxlen=config.moving_average_window)

        if resume:
            self._restore()
        elif (self.ckpt_dir / CHECKPOINT_FILE).exists():
            raise CheckpointError(
                f"{self.out_dir} already holds a training run ({self.ckpt_dir / CHECKPOINT_FILE});"
                " pass --resume to continue it or choose another --out"
            )

    # ----------------------------------------------------------------- state
    def _trainer_state(self, running: list[int]) -> dict[str, Any]:
        return {
            "env_steps": self.env_steps,
            "episodes_done": self.episodes_done,
            "next_episode": self.next_episode,
            "pending": [*running, *self.pending],
            "update_debt": self.update_debt,
            "wall_time_s": self.wall_time_s,
            "reset_failures": self.reset_failures,
            "clean_streak": self.clean_streak,
            "recent_returns": list(self.recent_returns),
            "rng": self.rng.bit_generator.state,
            "torch_rng": torch.get_rng_state(),
        }

    def _restore(self) -> None:
        ckpt = load_checkpoint(self.ckpt_dir, self.config)
        try:
            self.learner.load_state_dict(ckpt.learner)
            if ckpt.replay is not None:
                self.buffer.load_state_dict(ckpt.replay)
        except (KeyError, RuntimeError, ValueError) as exc:
            raise CheckpointError(f"checkpoint {ckpt.path} does not fit this run: {exc}") from exc
        t = ckpt.trainer
        self.env_steps = int(t["env_steps"])
        self.episodes_done = int(t["episodes_done"])
        self.next_episode = int(t["next_episode"])
        self.pending = deque(int(i) for i in t["pending"])
        self.update_debt = float(t["update_debt"])
        self.wall_time_s = float(t["wall_time_s"])
        self.reset_failures = int(t.get("reset_failures", 0))
        self.clean_streak = int(t.get("clean_streak", 0))
        self.recent_returns.extend(float(r) for r in t["recent_returns"])
        self.rng.bit_generator.state = t["rng"]
        torch.set_rng_state(t["torch_rng"])
        self._truncate_csv(self.episodes_done)
        log.info(
            "resumed %s at %d episodes, %d env steps, %d transitions in replay",
            ckpt.path, self.episodes_done, self.env_steps, len(self.buffer),
        )  # fmt: skip

    def _truncate_csv(self, rows: int) -> None:
        """Keep the header and the first ``rows`` episodes (those the checkpoint knows)."""
        if not self.csv_path.exists():
            if rows:
                log.warning("%s is missing; the resumed CSV starts empty", self.csv_path)
            return
        with self.csv_path.open(newline="") as f:
            lines = list(csv.reader(f))
        with self.csv_path.open("w", newline="") as f:
            csv.writer(f).writerows(lines[: rows + 1])

    def _checkpoint(self, running: list[int]) -> None:
        save_checkpoint(
            self.ckpt_dir,
            config=self.config,
            learner_state=self.learner.state_dict(),
            trainer_state=self._trainer_state(running),
            replay_state=self.buffer.state_dict() if self.config.save_replay else None,
        )
        log.info("checkpoint at %d episodes, %d env steps", self.episodes_done, self.env_steps)

    # ------------------------------------------------------------------ loop
    def _next_plan(self) -> EpisodePlan | None:
        if self.pending:
            return plan_episode(self.config, self.pending.popleft())
        if self.next_episode < self.config.episodes:
            self.next_episode += 1
            return plan_episode(self.config, self.next_episode - 1)
        return None

    def run(self) -> TrainResult:
        """Train until ``config.episodes`` episodes have finished (or the run is safe, with
        ``stop_when_safe``); returns the summary."""
        from torch.utils.tensorboard import SummaryWriter

        c = self.config
        self.out_dir.mkdir(parents=True, exist_ok=True)
        atomic_write_text(self.out_dir / "config.json", c.to_json())
        new_csv = not self.csv_path.exists()
        csv_file = self.csv_path.open("a", newline="")
        writer_csv = csv.DictWriter(csv_file, fieldnames=CSV_FIELDS)
        if new_csv:
            writer_csv.writeheader()
        tb = SummaryWriter(str(self.out_dir / "tb"), purge_step=self.env_steps or None)
        progress = _Progress(self.show_progress, c.episodes, self.episodes_done, f"train {c.mode}")
        vec: VecEnv | None = None
        self._session = (time.perf_counter(), self.env_steps, self.wall_time_s)
        try:
            vec = make_vec_env(self.env_factory, c.envs, self.subprocess_envs, INFO_KEYS)
            loop = _Loop(self, vec, tb, writer_csv, csv_file, progress)
            loop.run()
            self._checkpoint([])
        finally:
            progress.close()
            tb.close()
            csv_file.close()
            if vec is not None:
                vec.close()
        return self._finish()

    @property
    def safe_enough(self) -> bool:
        """Whether ``stop_when_safe`` consecutive episodes ran clean."""
        n = self.config.stop_when_safe
        return n is not None and self.clean_streak >= n

    def _tick(self) -> float:
        """Update the wall time; returns this session's env steps per second."""
        start, steps, wall = self._session
        now = time.perf_counter()
        self.wall_time_s = wall + now - start
        return (self.env_steps - steps) / max(now - start, 1e-9)

    def _new_episode(self, plan: EpisodePlan) -> _Episode:
        c = self.config
        shielded = c.safe_learning and plan.index < c.shielded_fraction * c.episodes
        return _Episode(plan, shielded, NStepQueue(c.n_step, c.gamma))

    def _owe(self, new_transitions: int) -> None:
        """Record the updates owed for ``new_transitions`` (one per ``train_frequency``)."""
        c = self.config
        if self.env_steps >= c.learning_starts and len(self.buffer) >= c.batch_size:
            self.update_debt += new_transitions / c.train_frequency

    def _train(self, tb: Any) -> None:
        """Run the gradient updates owed."""
        c = self.config
        while self.update_debt >= 1.0:
            self.update_debt -= 1.0
            stats = self.learner.update(self.buffer.sample(c.batch_size, self.rng), self.env_steps)
            if self.learner.updates % c.log_every_updates == 0:
                tb.add_scalar("losses/td_loss", stats["td_loss"], self.env_steps)
                tb.add_scalar("losses/q_values", stats["q_values"], self.env_steps)
                tb.add_scalar("charts/learning_rate", stats["learning_rate"], self.env_steps)
                if c.safe_learning:
                    tb.add_scalar("losses/unsafe_loss", stats["unsafe_loss"], self.env_steps)
                if c.grad_clip_norm is not None:
                    tb.add_scalar("losses/grad_norm", stats["grad_norm"], self.env_steps)

    def _log_episode(
        self, writer: csv.DictWriter, tb: Any, env: int, ep: _Episode, terminated: bool,
        eps: float, sps: float,
    ) -> None:  # fmt: skip
        self.episodes_done += 1
        self.clean_streak = self.clean_streak + 1 if ep.clean else 0
        self.recent_returns.append(ep.ret)
        shield_share = ep.greedy_unsafe / max(ep.length, 1)
        mean_speed = ep.speed_sum / max(ep.length, 1)
        row = {
            "episode": ep.plan.index, "env": env, "seed": ep.plan.seed,
            "traffic_level": ep.plan.traffic_level, "stops": int(ep.plan.has_stops),
            "return": round(ep.ret, 4), "length": ep.length, "env_steps": self.env_steps,
            "epsilon": round(eps, 5), **{k: int(v) for k, v in ep.flags.items()},
            "speeding_steps": ep.speeding_steps, "shield_share": round(shield_share, 5),
            "shielded": int(ep.shielded), "mean_speed_mps": round(mean_speed, 4),
            "distance_m": round(ep.distance_m, 2), "terminated": int(terminated),
            "truncated": int(not terminated), "wall_time_s": round(self.wall_time_s, 2),
        }  # fmt: skip
        writer.writerow(row)
        step = self.env_steps
        tb.add_scalar("charts/episodic_return", ep.ret, step)
        tb.add_scalar("charts/episodic_length", ep.length, step)
        tb.add_scalar("charts/epsilon", eps, step)
        tb.add_scalar("charts/steps_per_second", sps, step)
        tb.add_scalar("charts/mean_speed_mps", mean_speed, step)
        for key, value in ep.flags.items():
            tb.add_scalar(f"safety/{key}", float(value), step)
        tb.add_scalar("safety/speeding_steps", ep.speeding_steps, step)
        tb.add_scalar("safety/shield_share", shield_share, step)

    def _finish(self) -> TrainResult:
        c = self.config
        steps_per_s = self.env_steps / max(self.wall_time_s, 1e-9)
        card = {
            "name": c.mode,
            "mode": c.mode,
            "config": c.to_dict(),
            "episodes": self.episodes_done,
            "env_steps": self.env_steps,
            "updates": self.learner.updates,
            "wall_time_s": round(self.wall_time_s, 1),
            "steps_per_s": round(steps_per_s, 1),
            "num_envs": c.envs,
            "reset_failures": self.reset_failures,
            "stopped_early": self.safe_enough,
            "final_mean_return": (
                float(np.mean(self.recent_returns)) if self.recent_returns else None
            ),
            "git_commit": git_commit(),
            "torch_version": torch.__version__,
            "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
            "evaluation": None,
        }
        policy_path, _ = save_policy(self.out_dir / "policy.pt", self.learner.q, card)
        curve = plot_training_curve(
            self.csv_path,
            self.out_dir / "training_curve.png",
            c.moving_average_window,
            f"D3QN {c.mode}: training reward",
        )
        return TrainResult(
            self.out_dir, self.episodes_done, self.env_steps, self.learner.updates,
            self.wall_time_s, steps_per_s, policy_path, curve, self.safe_enough,
        )  # fmt: skip


class _Loop:
    """One session of the pipelined collection loop of a :class:`Trainer`."""

    def __init__(
        self, trainer: Trainer, vec: VecEnv, tb: Any, writer: csv.DictWriter, csv_file: Any,
        progress: _Progress,
    ) -> None:  # fmt: skip
        self.t = trainer
        self.vec = vec
        self.tb, self.writer, self.csv_file, self.progress = tb, writer, csv_file, progress
        n, dim = vec.num_envs, trainer.buffer.state_dim
        self.obs = np.zeros((n, dim), dtype=np.float32)
        self.masks = np.ones((n, N_ACTIONS), dtype=np.bool_)  # not penalised in obs
        self.allowed = np.ones((n, N_ACTIONS), dtype=np.bool_)  # kept by the shield in obs
        self.episodes: dict[int, _Episode] = {}
        self.starting: dict[int, EpisodePlan] = {}

    def run(self) -> None:
        t, c = self.t, self.t.config
        self._request(list(range(self.vec.num_envs)))
        while not t.safe_enough:
            if self.starting and not self.episodes:
                self._await_starts()
            if not self.episodes:
                return
            active = sorted(self.episodes)
            eps = t.learner.epsilon(t.env_steps)
            q = t.learner.q_values(self.obs[active])
            greedy = q.argmax(axis=-1)
            greedy_unsafe = ~self.allowed[active, greedy]
            act_mask = self.allowed[active].copy()
            act_mask[[not self.episodes[i].shielded for i in active]] = True
            actions = t.learner.explore(q, eps, t.rng, act_mask)
            self.vec.step_async(active, actions)
            t._train(self.tb)  # overlaps the workers' step
            next_obs, rewards, term, trunc, infos = self.vec.step_wait(active)
            self._await_starts()  # resets asked last iteration ran during this one
            next_allowed = runtime_mask(next_obs)
            self._store(active, actions, rewards, next_obs, next_allowed, term, trunc)
            t.env_steps += len(active)
            t._owe(len(active))
            self.obs[active] = next_obs
            self.masks[active] = training_mask(next_obs)
            self.allowed[active] = next_allowed
            sps = t._tick()
            finished = []
            for k, i in enumerate(active):
                ep = self.episodes[i]
                ep.record(float(rewards[k]), infos[k], bool(greedy_unsafe[k]))
                if term[k] or trunc[k]:
                    finished.append(i)
                    t._log_episode(self.writer, self.tb, i, ep, bool(term[k]), eps, sps)
                    del self.episodes[i]
            if finished:
                self.csv_file.flush()
                self.progress.update(
                    t.episodes_done, t.recent_returns[-1], float(np.mean(t.recent_returns)),
                    eps, sps,
                )  # fmt: skip
                self._request(finished)
                due = t.episodes_done % c.checkpoint_every_episodes == 0
                if due and t.episodes_done < c.episodes and not t.safe_enough:
                    t._checkpoint(self.running())
        if t.safe_enough:
            log.info("%d episodes in a row ran clean: training ends", t.clean_streak)

    def running(self) -> list[int]:
        """Indices of the episodes under way (restarted on resume)."""
        plans = [ep.plan for ep in self.episodes.values()] + list(self.starting.values())
        return sorted(p.index for p in plans)

    def _store(
        self, active: list[int], actions: np.ndarray, rewards: np.ndarray, next_obs: np.ndarray,
        next_allowed: np.ndarray, term: np.ndarray, trunc: np.ndarray,
    ) -> None:  # fmt: skip
        """Store the n-step transitions completed: each with the actions not penalised in its
        state and the actions the target may choose in its bootstrap state."""
        rows: list[Transition] = []
        for k, i in enumerate(active):
            rows += self.episodes[i].queue.push(
                self.obs[i].copy(), int(actions[k]), float(rewards[k]), self.masks[i].copy(),
                next_obs[k], next_allowed[k], bool(term[k]), bool(term[k] or trunc[k]),
            )  # fmt: skip
        if rows:
            o, a, r, o2, d, g, m, m2 = (np.asarray(col) for col in zip(*rows, strict=True))
            self.t.buffer.add(o, a, r, o2, d, g, m, m2)

    def _request(self, indices: list[int]) -> None:
        """Ask the free envs ``indices`` to start the next planned episodes."""
        starts = {}
        for i in indices:
            plan = self.t._next_plan()
            if plan is None:
                break
            starts[i] = plan
        self._reset(starts)

    def _reset(self, starts: dict[int, EpisodePlan]) -> None:
        if starts:
            ids = list(starts)
            plans = list(starts.values())
            self.vec.reset_async(ids, [p.seed for p in plans], [p.reset_options() for p in plans])
            self.starting.update(starts)

    def _await_starts(self) -> None:
        """Collect the resets asked for; an episode that cannot start gets a new seed."""
        for attempt in range(MAX_RESET_ATTEMPTS):
            if not self.starting:
                return
            ids = sorted(self.starting)
            first, infos = self.vec.reset_wait(ids)
            retry = {}
            for k, i in enumerate(ids):
                plan = self.starting.pop(i)
                if RESET_FAILED in infos[k]:
                    self.t.reset_failures += 1
                    log.warning("episode %d (seed %d) could not start: %s; new seed",
                                plan.index, plan.seed, infos[k][RESET_FAILED])  # fmt: skip
                    retry[i] = replace(plan, seed=reseed(plan.seed, attempt))
                else:
                    self.obs[i] = first[k]
                    self.masks[i] = training_mask(first[k])
                    self.allowed[i] = runtime_mask(first[k])
                    self.episodes[i] = self.t._new_episode(plan)
            self._reset(retry)
        if self.starting:
            raise RuntimeError(
                f"envs {sorted(self.starting)} failed to start an episode "
                f"{MAX_RESET_ATTEMPTS} times"
            )


def train(
    config: TrainConfig,
    out_dir: Path,
    env_factory: EnvFactory | None = None,
    resume: bool = False,
    show_progress: bool = False,
    subprocess_envs: bool | None = None,
) -> TrainResult:
    """Train one agent; see :class:`Trainer`."""
    return Trainer(config, out_dir, env_factory, resume, show_progress, subprocess_envs).run()
