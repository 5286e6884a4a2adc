"""The counters of a training run and their checkpoint form.

:class:`RunState` is what a run has done so far: env steps, finished episodes, the
episodes still to play, the updates it owes, the early-end streak, the recent returns, the
commits of the code that ran it and the RNG states. :meth:`RunState.state_dict` is the
``trainer`` entry of a checkpoint (:mod:`explaindrive.agent.checkpoint`) and
:meth:`RunState.load_state_dict` reads it back.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch


@dataclass
class RunState:
    """What a training run has done so far; see the module docstring.

    Build a new run's state with :meth:`start`.
    """

    rng: np.random.Generator  # draws the replay minibatches
    recent_returns: deque[float]  # returns of the last ``moving_average_window`` episodes
    source_commits: list[str | None]  # the code of the start and of each resume
    env_steps: int = 0
    episodes_done: int = 0
    next_episode: int = 0  # the first episode index not handed out yet
    pending: deque[int] = field(default_factory=deque)  # interrupted episodes, played first
    update_debt: float = 0.0  # gradient updates owed for the transitions stored
    wall_time_s: float = 0.0
    reset_failures: int = 0  # episode starts that failed and got a new seed
    lost_rounds: int = 0  # rounds lost to a worker that died (Ray restarts it)
    clean_streak: int = 0  # consecutive finished episodes without override or violation

    @classmethod
    def start(cls, seed: int, window: int, commit: str | None) -> RunState:
        """The state of a new run.

        Args:
            seed: the run's seed (the minibatch RNG is seeded with ``[seed, 1]``).
            window: how many recent returns to keep.
            commit: the commit of the code that starts the run, if known.
        """
        return cls(np.random.default_rng([seed, 1]), deque(maxlen=window), [commit])

    @property
    def mean_return(self) -> float | None:
        """Mean of the recent returns; None before the first episode."""
        return float(np.mean(self.recent_returns)) if self.recent_returns else None

    def state_dict(self, in_flight: Iterable[int] = ()) -> dict[str, Any]:
        """The checkpoint's ``trainer`` entry, with torch's global RNG state.

        Args:
            in_flight: episodes under way in the workers; saved ahead of :attr:`pending`,
                so a resumed run plays them first.
        """
        return {
            "env_steps": self.env_steps,
            "episodes_done": self.episodes_done,
            "next_episode": self.next_episode,
            "pending": [*in_flight, *self.pending],
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

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Continue from what :meth:`state_dict` returned; sets torch's global RNG too.

        The commit this state started with is added to the saved ones unless it is the
        last of them. A state saved without ``reset_failures``, ``lost_rounds``,
        ``clean_streak`` or ``source_commits`` counts 0 (and an unknown first commit).

        Raises:
            KeyError: if ``state`` lacks a counter every checkpoint holds.
            ValueError: if ``state`` holds an RNG state of another kind.
        """
        # a checkpoint written before commits were kept does not know where the run started
        earlier = list(state.get("source_commits", [None]))
        rng = np.random.default_rng()
        rng.bit_generator.state = state["rng"]
        torch_rng = state["torch_rng"]
        self.env_steps = int(state["env_steps"])
        self.episodes_done = int(state["episodes_done"])
        self.next_episode = int(state["next_episode"])
        self.pending = deque(int(i) for i in state["pending"])
        self.update_debt = float(state["update_debt"])
        self.wall_time_s = float(state["wall_time_s"])
        self.reset_failures = int(state.get("reset_failures", 0))
        self.lost_rounds = int(state.get("lost_rounds", 0))
        self.clean_streak = int(state.get("clean_streak", 0))
        self.recent_returns.clear()
        self.recent_returns.extend(float(r) for r in state["recent_returns"])
        self.source_commits = earlier + [c for c in self.source_commits if c != earlier[-1]]
        self.rng = rng
        torch.set_rng_state(torch_rng)
