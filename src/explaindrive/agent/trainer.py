"""The training loop: rollout workers, D3QN updates, logs, checkpoints and resume.

Outputs of a run directory ``out``:

- ``episodes.csv``: one row per finished episode (return, length, safety flags, speed, the
  share of steps whose greedy action the shield would override...);
- ``tb/``: TensorBoard scalars (``charts/episodic_return``, ``charts/epsilon``,
  ``charts/steps_per_second``, ``losses/td_loss``, ``losses/q_values``...), x = env steps,
  with the ``tensorboard`` extra;
- ``checkpoints/``: the last checkpoint (see :mod:`explaindrive.agent.checkpoint`);
- ``policy.pt`` + ``policy.json``: the final greedy policy and its card;
- ``training_curve.png``: episode reward with its moving average (the paper's figure);
- ``train.log``: what the run reported (resumes, reset failures, lost workers, early end).

The loop runs in rounds. In each round every worker (:mod:`explaindrive.agent.rollout`;
local processes or Ray actors, :mod:`explaindrive.agent.workers`) plays ``rollout_steps``
steps with the weights of the round's start, while the learner makes the updates owed for
the transitions already stored (one per ``train_frequency`` transitions after
``learning_starts``); then the round's transitions go into the replay buffer. New weights go
out with every round. No decision depends on timing, so a run is reproducible.

Resume: the checkpoint holds the networks, the optimiser, the replay buffer, the counters,
the RNG state and the episodes that were under way; ``resume=True`` reloads it, truncates
the CSV to the episodes it had logged, and plays the interrupted episodes again with their
original plans. Only the transitions collected after the checkpoint are lost. A run that
is not resumed writes ``episodes.csv`` afresh: the rows of a run stopped before its first
checkpoint cannot be continued, and are never counted twice.
"""

from __future__ import annotations

import csv
import logging
import time
from collections import deque
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import torch

from explaindrive.agent.buffer import ReplayBuffer
from explaindrive.agent.checkpoint import (
    CHECKPOINT_FILE,
    POLICY_FILE,
    CheckpointError,
    atomic_write_text,
    load_checkpoint,
    save_checkpoint,
    save_policy,
)
from explaindrive.agent.config import TrainConfig
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.pool import WorkerLost, WorkerPool
from explaindrive.agent.rollout import CollectRequest, EnvFactory, Rollout, default_env_factory
from explaindrive.agent.run_log import (
    CSV_FIELDS,
    Progress,
    csv_row,
    git_commit,
    plot_training_curve,
    scalar_writer,
    tb_episode,
    truncate_csv,
)
from explaindrive.agent.workers import make_pool

log = logging.getLogger(__name__)


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
        use_ray: run the workers as Ray actors (on a local Ray unless ``ray_address``).
        ray_address: the Ray cluster to run the workers on (implies ``use_ray``).

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
        use_ray: bool = False,
        ray_address: str | None = None,
    ) -> None:
        self.config = config
        self.out_dir = Path(out_dir)
        self.ckpt_dir = self.out_dir / "checkpoints"
        self.csv_path = self.out_dir / "episodes.csv"
        self.env_factory = env_factory or default_env_factory(config)
        self.show_progress = show_progress
        self.pool_options: dict[str, Any] = {
            "subprocess": subprocess_envs, "use_ray": use_ray, "ray_address": ray_address,
        }  # fmt: skip
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
        self.lost_rounds = 0  # rounds lost to a worker that died (Ray restarts it)
        self.clean_streak = 0  # consecutive finished episodes without override or violation
        self.recent_returns: deque[float] = deque(maxlen=config.moving_average_window)
        self.source_commits = [git_commit()]  # the code of the start and of each resume

        self.resumed = resume  # else episodes.csv starts afresh: no rows counted twice
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
            "lost_rounds": self.lost_rounds,
            "clean_streak": self.clean_streak,
            "recent_returns": list(self.recent_returns),
            "source_commits": self.source_commits,
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
        self.lost_rounds = int(t.get("lost_rounds", 0))
        self.clean_streak = int(t.get("clean_streak", 0))
        self.recent_returns.extend(float(r) for r in t["recent_returns"])
        # a checkpoint written before commits were kept does not know where the run started
        earlier = list(t.get("source_commits", [None]))
        self.source_commits = earlier + [c for c in self.source_commits if c != earlier[-1]]
        self.rng.bit_generator.state = t["rng"]
        torch.set_rng_state(t["torch_rng"])
        if not truncate_csv(self.csv_path, self.episodes_done) and self.episodes_done:
            log.warning("%s is missing; the resumed CSV starts empty", self.csv_path)
        self.note(
            logging.INFO, "resumed %s at %d episodes, %d env steps, %d transitions in replay",
            ckpt.path, self.episodes_done, self.env_steps, len(self.buffer),
        )  # fmt: skip

    def note(self, level: int, message: str, *args: object) -> None:
        """Log ``message`` and append it to the run's ``train.log``."""
        log.log(level, message, *args)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        stamp = datetime.now(UTC).isoformat(timespec="seconds")
        with (self.out_dir / "train.log").open("a", encoding="utf-8") as f:
            f.write(f"{stamp} {logging.getLevelName(level)} {message % args}\n")

    def _checkpoint(self, running: list[int]) -> None:
        save_checkpoint(
            self.ckpt_dir,
            config=self.config,
            learner_state=self.learner.state_dict(),
            trainer_state=self._trainer_state(running),
            replay_state=self.buffer.state_dict() if self.config.save_replay else None,
        )
        self.note(logging.INFO, "checkpoint at %d episodes, %d env steps", self.episodes_done,
                  self.env_steps)  # fmt: skip

    # ------------------------------------------------------------------ loop
    def run(self) -> TrainResult:
        """Train until ``config.episodes`` episodes have finished (or the run is safe, with
        ``stop_when_safe``); returns the summary."""
        c = self.config
        self.out_dir.mkdir(parents=True, exist_ok=True)
        atomic_write_text(self.out_dir / "config.json", c.to_json())
        new_csv = not self.resumed or not self.csv_path.exists()
        if not self.resumed and self.csv_path.exists():  # a run stopped before its checkpoint
            self.note(logging.WARNING, "%s held episodes of a run that left no checkpoint; "
                      "this run starts it afresh", self.csv_path)  # fmt: skip
        csv_file = self.csv_path.open("w" if new_csv else "a", newline="")
        writer = csv.DictWriter(csv_file, fieldnames=CSV_FIELDS)
        if new_csv:
            writer.writeheader()
        tb = scalar_writer(self.out_dir / "tb", purge_step=self.env_steps or None)
        progress = Progress(self.show_progress, c.episodes, self.episodes_done, f"train {c.mode}")
        pool: WorkerPool | None = None
        self._session = (time.perf_counter(), self.env_steps, self.wall_time_s)
        try:
            pool = make_pool(c, self.env_factory, c.envs, **self.pool_options)
            rounds = _Rounds(self, pool, tb, writer, csv_file, progress)
            rounds.run()
            self._train(tb)  # the updates owed for the last round
            self._checkpoint([])
        finally:
            progress.close()
            tb.close()
            csv_file.close()
            if pool is not None:
                pool.close()
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

    def _next_index(self) -> int | None:
        """The next episode to play: an interrupted one first, then a new one."""
        if self.pending:
            return self.pending.popleft()
        if self.next_episode < self.config.episodes:
            self.next_episode += 1
            return self.next_episode - 1
        return None

    def _owe(self, before: int) -> None:
        """Record the updates owed for the transitions after ``before`` env steps: one per
        ``train_frequency`` transitions once ``learning_starts`` have been collected."""
        c = self.config
        counted = self.env_steps - max(before, c.learning_starts)
        if counted > 0:
            self.update_debt += counted / c.train_frequency

    def _train(self, tb: Any) -> None:
        """Run the gradient updates owed."""
        c = self.config
        while self.update_debt >= 1.0 and len(self.buffer) >= c.batch_size:
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
            "lost_rounds": self.lost_rounds,
            "stopped_early": self.safe_enough,
            "final_mean_return": (
                float(np.mean(self.recent_returns)) if self.recent_returns else None
            ),
            "git_commit": self.source_commits[0],
            "git_commits": self.source_commits,
            "torch_version": torch.__version__,
            "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
            "evaluation": None,
        }
        policy_path, _ = save_policy(self.out_dir / POLICY_FILE, self.learner.q, card)
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


class _Rounds:
    """One session of the round loop of a :class:`Trainer` (see the module docstring)."""

    def __init__(
        self, trainer: Trainer, pool: WorkerPool, tb: Any, writer: csv.DictWriter, csv_file: Any,
        progress: Progress,
    ) -> None:  # fmt: skip
        self.t, self.pool = trainer, pool
        self.tb, self.writer, self.csv_file, self.progress = tb, writer, csv_file, progress
        n = pool.num_workers
        self.running: list[int | None] = [None] * n  # episode under way per worker
        self.reserved: list[int | None] = [None] * n  # episode a worker starts next
        self.sent_updates = -1  # learner updates of the weights the workers hold
        every = trainer.config.checkpoint_every_episodes
        self.checkpoint_block = trainer.episodes_done // every

    def run(self) -> None:
        t = self.t
        while not t.safe_enough:
            self.reserved = [r if r is not None else t._next_index() for r in self.reserved]
            if all(i is None for i in (*self.running, *self.reserved)):
                return
            epsilon = t.learner.epsilon(t.env_steps)
            self.pool.submit(self._requests(epsilon))
            t._train(self.tb)  # overlaps the workers' round
            results = self.pool.gather()
            sps = t._tick()
            for worker, result in enumerate(results):
                self._absorb(worker, result, epsilon, sps)
            self.csv_file.flush()
            self._maybe_checkpoint()
        t.note(logging.INFO, "%d episodes in a row ran clean: training ends", t.clean_streak)

    def in_flight(self) -> list[int]:
        """Episodes under way or reserved (played again on resume)."""
        return sorted(i for i in (*self.running, *self.reserved) if i is not None)

    def _requests(self, epsilon: float) -> list[CollectRequest]:
        t = self.t
        weights = None
        if t.learner.updates != self.sent_updates:
            weights = {k: v.detach().clone() for k, v in t.learner.q.state_dict().items()}
            self.sent_updates = t.learner.updates
        steps = t.config.rollout_steps
        return [CollectRequest(steps, epsilon, weights, start) for start in self.reserved]

    def _absorb(
        self, worker: int, result: Rollout | WorkerLost, epsilon: float, sps: float
    ) -> None:
        t = self.t
        if isinstance(result, WorkerLost):
            lost = [i for i in (self.running[worker], self.reserved[worker]) if i is not None]
            t.note(
                logging.WARNING,
                "worker %d died (%s) and was restarted; its round is discarded and "
                "episode(s) %s will be played again", worker, result.reason, lost,
            )  # fmt: skip
            t.lost_rounds += 1
            t.pending.extendleft(reversed(lost))
            self.running[worker] = self.reserved[worker] = None
            return
        if result.started:
            self.reserved[worker] = None
        self.running[worker] = result.running
        if result.reset_failures:
            t.reset_failures += result.reset_failures
            t.note(logging.WARNING, "worker %d: %d episode start(s) failed and got a new seed",
                   worker, result.reset_failures)  # fmt: skip
        if result.transitions:
            columns = (np.asarray(col) for col in zip(*result.transitions, strict=True))
            t.buffer.add(*columns)
        before = t.env_steps
        for ep in result.episodes:
            t.env_steps = before + ep.ended_at_step
            self._log_episode(worker, ep, epsilon, sps)
        t.env_steps = before + result.steps
        t._owe(before)

    def _log_episode(self, worker: int, ep: Any, epsilon: float, sps: float) -> None:
        t = self.t
        t.episodes_done += 1
        t.clean_streak = t.clean_streak + 1 if ep.clean else 0
        t.recent_returns.append(ep.ret)
        self.writer.writerow(csv_row(ep, worker, t.env_steps, epsilon, t.wall_time_s))
        tb_episode(self.tb, ep, t.env_steps, epsilon, sps)
        avg = float(np.mean(t.recent_returns))
        self.progress.update(t.episodes_done, ep.ret, avg, epsilon, sps)

    def _maybe_checkpoint(self) -> None:
        t = self.t
        block = t.episodes_done // t.config.checkpoint_every_episodes
        if block > self.checkpoint_block and t.episodes_done < t.config.episodes:
            self.checkpoint_block = block
            if not t.safe_enough:
                t._checkpoint(self.in_flight())


def train(
    config: TrainConfig,
    out_dir: Path,
    env_factory: EnvFactory | None = None,
    resume: bool = False,
    show_progress: bool = False,
    subprocess_envs: bool | None = None,
    use_ray: bool = False,
    ray_address: str | None = None,
) -> TrainResult:
    """Train one agent; see :class:`Trainer`."""
    trainer = Trainer(config, out_dir, env_factory, resume, show_progress, subprocess_envs,
                      use_ray, ray_address)  # fmt: skip
    return trainer.run()
