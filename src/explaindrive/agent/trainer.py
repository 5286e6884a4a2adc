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
the RNG state and the episodes that were under way
(:class:`~explaindrive.agent.run_state.RunState`); ``resume=True`` reloads it, truncates
the CSV to the episodes it had logged, and plays the interrupted episodes again with their
original plans. Only the transitions collected after the checkpoint are lost. A run that
is not resumed writes ``episodes.csv`` afresh: the rows of a run stopped before its first
checkpoint cannot be continued, and are never counted twice.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import torch

from explaindrive.agent.boundary import boundary_batch
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
from explaindrive.agent.prioritized import PrioritizedReplayBuffer
from explaindrive.agent.rollout import CollectRequest, EnvFactory, Rollout, default_env_factory
from explaindrive.agent.run_log import RunLog, git_commit, note, plot_training_curve, truncate_csv
from explaindrive.agent.run_state import RunState
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
        self.buffer = (
            PrioritizedReplayBuffer(config.buffer_size, config.priority_alpha)
            if config.priority_alpha > 0.0
            else ReplayBuffer(config.buffer_size)
        )
        self.state = RunState.start(config.seed, config.moving_average_window, git_commit())
        self.resumed = resume  # else episodes.csv starts afresh: no rows counted twice
        if resume:
            self._restore()
        elif (self.ckpt_dir / CHECKPOINT_FILE).exists():
            raise CheckpointError(
                f"{self.out_dir} already holds a training run ({self.ckpt_dir / CHECKPOINT_FILE});"
                " pass --resume to continue it or choose another --out"
            )

    def _restore(self) -> None:
        ckpt = load_checkpoint(self.ckpt_dir, self.config)
        try:
            self.learner.load_state_dict(ckpt.learner)
            if ckpt.replay is not None:
                self.buffer.load_state_dict(ckpt.replay)
            self.state.load_state_dict(ckpt.trainer)
        except (KeyError, RuntimeError, ValueError) as exc:
            raise CheckpointError(f"checkpoint {ckpt.path} does not fit this run: {exc}") from exc
        s = self.state
        if not truncate_csv(self.csv_path, s.episodes_done) and s.episodes_done:
            log.warning("%s is missing; the resumed CSV starts empty", self.csv_path)
        self.note(
            logging.INFO, "resumed %s at %d episodes, %d env steps, %d transitions in replay",
            ckpt.path, s.episodes_done, s.env_steps, len(self.buffer),
        )  # fmt: skip

    def note(self, level: int, message: str, *args: object) -> None:
        """Log ``message`` and append it to the run's ``train.log``."""
        note(self.out_dir, level, message, *args)

    def _checkpoint(self, in_flight: list[int]) -> None:
        """Save the run, with the episodes under way in the workers (``in_flight``)."""
        save_checkpoint(
            self.ckpt_dir,
            config=self.config,
            learner_state=self.learner.state_dict(),
            trainer_state=self.state.state_dict(in_flight),
            replay_state=self.buffer.state_dict() if self.config.save_replay else None,
        )
        self.note(logging.INFO, "checkpoint at %d episodes, %d env steps",
                  self.state.episodes_done, self.state.env_steps)  # fmt: skip

    @property
    def safe_enough(self) -> bool:
        """Whether ``stop_when_safe`` consecutive episodes ran clean."""
        n = self.config.stop_when_safe
        return n is not None and self.state.clean_streak >= n

    # ------------------------------------------------------------------ loop
    def run(self) -> TrainResult:
        """Train until ``config.episodes`` episodes have finished (or the run is safe, with
        ``stop_when_safe``); returns the summary."""
        c, s = self.config, self.state
        self.out_dir.mkdir(parents=True, exist_ok=True)
        atomic_write_text(self.out_dir / "config.json", c.to_json())
        if not self.resumed and self.csv_path.exists():  # a run stopped before its checkpoint
            self.note(logging.WARNING, "%s held episodes of a run that left no checkpoint; "
                      "this run starts it afresh", self.csv_path)  # fmt: skip
        out = RunLog(self.out_dir, c, append=self.resumed, env_steps=s.env_steps,
                     episodes_done=s.episodes_done, show_progress=self.show_progress)  # fmt: skip
        pool: WorkerPool | None = None
        self._session = (time.perf_counter(), s.env_steps, s.wall_time_s)
        try:
            pool = make_pool(c, self.env_factory, c.envs, **self.pool_options)
            self._rounds(pool, out)
            self._train(out)  # the updates owed for the last round
            self._checkpoint([])
        finally:
            out.close()
            if pool is not None:
                pool.close()
        return self._finish()

    def _rounds(self, pool: WorkerPool, out: RunLog) -> None:
        """The round loop (see the module docstring), until no episode is left to play or
        the run is safe enough."""
        c, s = self.config, self.state
        running: list[int | None] = [None] * pool.num_workers  # episode under way per worker
        reserved: list[int | None] = [None] * pool.num_workers  # episode it starts next
        sent_updates = -1  # learner updates of the weights the workers hold
        checkpoint_block = s.episodes_done // c.checkpoint_every_episodes
        while not self.safe_enough:
            reserved = [r if r is not None else self._next_index() for r in reserved]
            if all(i is None for i in (*running, *reserved)):
                return
            epsilon = self.learner.epsilon(s.env_steps)
            weights = None
            if self.learner.updates != sent_updates:
                weights = {k: v.detach().clone() for k, v in self.learner.q.state_dict().items()}
                sent_updates = self.learner.updates
            pool.submit([CollectRequest(c.rollout_steps, epsilon, weights, start)
                         for start in reserved])  # fmt: skip
            self._train(out)  # overlaps the workers' round
            results = pool.gather()
            sps = self._tick()
            for worker, result in enumerate(results):
                if isinstance(result, WorkerLost):
                    lost = [i for i in (running[worker], reserved[worker]) if i is not None]
                    self._lose(result, lost)
                    running[worker] = reserved[worker] = None
                    continue
                if result.started:
                    reserved[worker] = None
                running[worker] = result.running
                self._absorb(worker, result, epsilon, sps, out)
            out.flush()
            block = s.episodes_done // c.checkpoint_every_episodes
            if block > checkpoint_block and s.episodes_done < c.episodes:
                checkpoint_block = block
                if not self.safe_enough:  # episodes under way or reserved are played again
                    self._checkpoint(sorted(i for i in (*running, *reserved) if i is not None))
        self.note(logging.INFO, "%d episodes in a row ran clean: training ends", s.clean_streak)

    def _next_index(self) -> int | None:
        """The next episode to play: an interrupted one first, then a new one."""
        s = self.state
        if s.pending:
            return s.pending.popleft()
        if s.next_episode < self.config.episodes:
            s.next_episode += 1
            return s.next_episode - 1
        return None

    def _lose(self, lost_round: WorkerLost, episodes: list[int]) -> None:
        """A worker died: its round is discarded, and its ``episodes`` go first in line."""
        self.note(
            logging.WARNING,
            "worker %d died (%s) and was restarted; its round is discarded and "
            "episode(s) %s will be played again", lost_round.worker, lost_round.reason, episodes,
        )  # fmt: skip
        self.state.lost_rounds += 1
        self.state.pending.extendleft(reversed(episodes))

    def _absorb(
        self, worker: int, result: Rollout, epsilon: float, sps: float, out: RunLog
    ) -> None:
        """A worker's round: its transitions into the buffer, its episodes into the logs."""
        s = self.state
        if result.reset_failures:
            s.reset_failures += result.reset_failures
            self.note(logging.WARNING, "worker %d: %d episode start(s) failed and got a new seed",
                      worker, result.reset_failures)  # fmt: skip
        self.buffer.extend(result.transitions)
        before = s.env_steps
        for ep in result.episodes:
            s.env_steps = before + ep.ended_at_step
            s.episodes_done += 1
            s.clean_streak = s.clean_streak + 1 if ep.clean else 0
            s.recent_returns.append(ep.ret)
            out.episode(
                ep, worker, env_steps=s.env_steps, epsilon=epsilon, wall_time_s=s.wall_time_s,
                steps_per_s=sps, episodes_done=s.episodes_done, mean_return=s.mean_return or 0.0,
            )  # fmt: skip
        s.env_steps = before + result.steps
        # one update owed per ``train_frequency`` transitions after ``learning_starts``
        counted = s.env_steps - max(before, self.config.learning_starts)
        if counted > 0:
            s.update_debt += counted / self.config.train_frequency

    def _train(self, out: RunLog) -> None:
        """Run the gradient updates owed."""
        c, s = self.config, self.state
        while s.update_debt >= 1.0 and len(self.buffer) >= c.batch_size:
            s.update_debt -= 1.0
            buffer = self.buffer
            if isinstance(buffer, PrioritizedReplayBuffer):
                batch = buffer.sample(c.batch_size, s.rng, self.learner.priority_beta(s.env_steps))
            else:
                batch = buffer.sample(c.batch_size, s.rng)
            boundary = None
            if c.safe_learning and c.boundary_weight > 0.0:
                noise_max = c.obs_noise_max if c.boundary_noise else (0.0, 0.0)
                boundary = boundary_batch(
                    batch.obs,
                    s.rng,
                    c.dilemma_braking,
                    noise_max,
                    c.noisy_share,
                    speed_limiter=c.speed_limiter,
                )
            stats = self.learner.update(batch, s.env_steps, boundary)
            if isinstance(buffer, PrioritizedReplayBuffer):
                assert batch.indices is not None and stats.abs_td_errors is not None
                buffer.update_priorities(batch.indices, stats.abs_td_errors)
            if self.learner.updates % c.log_every_updates == 0:
                out.losses(stats, s.env_steps)

    def _tick(self) -> float:
        """Update the wall time; returns this session's env steps per second."""
        start, steps, wall = self._session
        now = time.perf_counter()
        self.state.wall_time_s = wall + now - start
        return (self.state.env_steps - steps) / max(now - start, 1e-9)

    def _finish(self) -> TrainResult:
        c, s = self.config, self.state
        steps_per_s = s.env_steps / max(s.wall_time_s, 1e-9)
        card = {
            "name": c.mode,
            "mode": c.mode,
            "config": c.to_dict(),
            "episodes": s.episodes_done,
            "env_steps": s.env_steps,
            "updates": self.learner.updates,
            "wall_time_s": round(s.wall_time_s, 1),
            "steps_per_s": round(steps_per_s, 1),
            "num_envs": c.envs,
            "reset_failures": s.reset_failures,
            "lost_rounds": s.lost_rounds,
            "stopped_early": self.safe_enough,
            "final_mean_return": s.mean_return,
            "git_commit": s.source_commits[0],
            "git_commits": s.source_commits,
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
            self.out_dir, s.episodes_done, s.env_steps, self.learner.updates,
            s.wall_time_s, steps_per_s, policy_path, curve, self.safe_enough,
        )  # fmt: skip


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
