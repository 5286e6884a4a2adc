"""The D3QN learner: online and target networks, optimiser, action selection, updates."""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from explaindrive.agent.buffer import ReplayBatch
from explaindrive.agent.config import TrainConfig
from explaindrive.agent.network import DuelingQNetwork
from explaindrive.agent.targets import (
    double_dqn_target,
    linear_schedule,
    td_loss,
    unsafe_action_loss,
)
from explaindrive.env.actions import N_ACTIONS
from explaindrive.env.safety import limit_mask


@dataclass(frozen=True, slots=True)
class UpdateStats:
    """What one gradient step did (the run log's TensorBoard scalars)."""

    td_loss: float
    unsafe_loss: float
    """0 without ``safe_learning``."""
    q_values: float
    """Mean Q of the taken actions."""
    learning_rate: float
    grad_norm: float
    """Before clipping; 0 when clipping is off."""
    boundary_loss: float = 0.0
    """The unsafe-action loss on synthetic boundary observations (0 without them)."""
    abs_td_errors: np.ndarray | None = None
    """|target - Q| of each row (prioritised replay's new priorities); ``None`` without it."""


class D3QNLearner:
    """Dueling double DQN with a hard or Polyak-averaged target network.

    Args:
        config: the training config (network, optimiser and target settings).
        seed: seeds the network initialisation (``config.seed`` when omitted).
    """

    def __init__(self, config: TrainConfig, seed: int | None = None) -> None:
        self.config = config
        torch.manual_seed(config.seed if seed is None else seed)
        self.q = DuelingQNetwork(config.hidden_sizes, near_range_m=config.near_range_m)
        self.q_target = copy.deepcopy(self.q)
        self.q_target.requires_grad_(False)
        self.optimizer = torch.optim.Adam(self.q.parameters(), lr=config.lr)
        self.updates = 0

    def epsilon(self, env_steps: int) -> float:
        """Exploration rate after ``env_steps`` transitions: linear decay to ``eps_end``, then
        ``eps_final`` from ``eps_final_after`` on (if set)."""
        c = self.config
        if c.eps_final is not None and env_steps >= c.eps_final_after:
            return c.eps_final
        return linear_schedule(c.eps_start, c.eps_end, c.eps_decay_steps, env_steps)

    def learning_rate(self, env_steps: int) -> float:
        """Learning rate after ``env_steps`` transitions (constant unless ``lr_final`` is set)."""
        c = self.config
        if c.lr_final is None:
            return c.lr
        return linear_schedule(c.lr, c.lr_final, c.lr_decay_steps, env_steps)

    def priority_beta(self, env_steps: int) -> float:
        """Importance-sampling exponent of prioritised replay after ``env_steps``
        transitions: linear from ``priority_beta`` to 1 over ``priority_beta_steps``."""
        c = self.config
        return linear_schedule(c.priority_beta, 1.0, c.priority_beta_steps, env_steps)

    @torch.no_grad()
    def q_values(self, obs: np.ndarray) -> np.ndarray:
        """Online Q-values of a batch of raw observations, shape ``(B, n_actions)``."""
        obs = np.asarray(obs, dtype=np.float32).reshape(-1, self.q.state_dim)
        return self.q(torch.from_numpy(obs)).numpy()

    @staticmethod
    def explore(
        q_values: np.ndarray,
        epsilon: float,
        rng: np.random.Generator,
        mask: np.ndarray | None = None,
    ) -> np.ndarray:
        """Epsilon-greedy actions from Q-values; with a ``mask`` (bool, one row per state),
        a chosen action the mask forbids becomes the best-valued allowed one."""
        greedy = q_values.argmax(axis=-1)
        explore = rng.random(len(q_values)) < epsilon
        random_actions = rng.integers(0, N_ACTIONS, size=len(q_values))
        actions = np.where(explore, random_actions, greedy).astype(np.int64)
        if mask is not None:
            allowed = mask[np.arange(len(actions)), actions]
            actions = np.where(allowed, actions, D3QNLearner.best_actions(q_values, mask))
        return actions

    @staticmethod
    def best_actions(q_values: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
        """The best-valued action of each row; with a ``mask``, the best-valued allowed one."""
        return (q_values if mask is None else np.where(mask, q_values, -np.inf)).argmax(axis=-1)

    def act(
        self,
        obs: np.ndarray,
        epsilon: float,
        rng: np.random.Generator,
        mask: np.ndarray | None = None,
    ) -> np.ndarray:
        """Epsilon-greedy actions for a batch of raw observations, in one forward pass."""
        return self.explore(self.q_values(obs), epsilon, rng, mask)

    def _margins(self, obs: np.ndarray) -> float | torch.Tensor | None:
        """The unsafe-action loss's margins for raw observations ``obs``: ``unsafe_margin``,
        or with ``limit_margin`` one per action, that one where the action exceeds the posted
        limit at the speed the network sees."""
        c = self.config
        if c.limit_margin is None or c.unsafe_margin is None:
            return c.unsafe_margin
        over_limit = torch.from_numpy(~limit_mask(obs))
        return torch.where(over_limit, c.limit_margin, c.unsafe_margin)

    def update(
        self,
        batch: ReplayBatch,
        env_steps: int,
        boundary: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> UpdateStats:
        """One gradient step on a minibatch; updates the target network when due.

        With ``safe_learning`` the double-DQN argmax runs over the safe actions of the next
        state and the unsafe actions of the state are pushed down to ``unsafe_q``; with
        ``boundary`` (synthetic observations and their masks,
        :mod:`explaindrive.agent.boundary`) the unsafe actions of those are pushed down
        too, weighted by ``boundary_weight``.
        """
        c = self.config
        lr = self.learning_rate(env_steps)
        for group in self.optimizer.param_groups:
            group["lr"] = lr
        obs = torch.from_numpy(batch.obs)
        next_obs = torch.from_numpy(batch.next_obs)
        actions = torch.from_numpy(batch.actions).long()
        rewards = torch.from_numpy(batch.rewards)
        terminated = torch.from_numpy(batch.terminated)

        extra = [torch.from_numpy(boundary[0])] if boundary is not None else []
        q_all = self.q(torch.cat([obs, next_obs, *extra]))  # one forward pass for all
        n = len(obs)
        q_obs, next_online = q_all[:n], q_all[n : 2 * n].detach()
        with torch.no_grad():
            next_target = self.q_target(next_obs)
        discount = torch.from_numpy(batch.discount)
        next_mask = torch.from_numpy(batch.next_mask) if c.safe_learning else None
        target = double_dqn_target(
            rewards, terminated, next_online, next_target, discount, next_mask
        )
        q_taken = q_obs.gather(1, actions.unsqueeze(1)).squeeze(1)
        weights = None if batch.weights is None else torch.from_numpy(batch.weights)
        loss = td = td_loss(q_taken, target, c.loss, c.huber_delta, weights)
        unsafe = on_boundary = torch.zeros(())
        if c.safe_learning:
            mask = torch.from_numpy(batch.mask)
            unsafe = unsafe_action_loss(
                q_obs, mask, c.unsafe_q, c.loss, c.huber_delta, self._margins(batch.obs)
            )
            loss = td + c.unsafe_loss_weight * unsafe
            if boundary is not None:
                margin = (
                    self._margins(boundary[0]) if c.boundary_margin is None else c.boundary_margin
                )
                on_boundary = unsafe_action_loss(
                    q_all[2 * n :], torch.from_numpy(boundary[1]), c.unsafe_q, c.loss,
                    c.huber_delta, margin,
                )  # fmt: skip
                loss = loss + c.boundary_weight * on_boundary

        self.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        grad_norm = 0.0
        if c.grad_clip_norm is not None:
            grad_norm = float(torch.nn.utils.clip_grad_norm_(self.q.parameters(), c.grad_clip_norm))
        self.optimizer.step()
        self.updates += 1
        if self.updates % c.target_update_interval == 0:
            self.update_target(c.tau)
        return UpdateStats(
            td_loss=float(td.detach()),
            unsafe_loss=float(unsafe.detach()),
            boundary_loss=float(on_boundary.detach()),
            q_values=float(q_taken.detach().mean()),
            learning_rate=lr,
            grad_norm=grad_norm,
            abs_td_errors=(None if weights is None else (target - q_taken.detach()).abs().numpy()),
        )

    @torch.no_grad()
    def update_target(self, tau: float) -> None:
        """``target <- tau * online + (1 - tau) * target`` (tau = 1: hard copy)."""
        for t, o in zip(self.q_target.parameters(), self.q.parameters(), strict=True):
            if tau >= 1.0:
                t.copy_(o)
            else:
                t.mul_(1.0 - tau).add_(o, alpha=tau)

    def state_dict(self) -> dict[str, Any]:
        """Everything needed to continue training (networks, optimiser, update count)."""
        return {
            "q": self.q.state_dict(),
            "q_target": self.q_target.state_dict(),
            "optimizer": self.optimizer.state_dict(),
            "updates": self.updates,
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (raises ``RuntimeError``/``KeyError`` on a mismatch)."""
        self.q.load_state_dict(state["q"])
        self.q_target.load_state_dict(state["q_target"])
        self.optimizer.load_state_dict(state["optimizer"])
        self.updates = int(state["updates"])
