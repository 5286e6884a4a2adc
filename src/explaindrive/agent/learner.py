"""The D3QN learner: online and target networks, optimiser, action selection, updates."""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any, NamedTuple

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


class _OnlineQ(NamedTuple):
    """The online network's Q-values in one update (one forward pass)."""

    states: torch.Tensor
    """Of the batch's states, ``(B, n_actions)``."""
    taken: torch.Tensor
    """Of the taken actions, ``(B,)``."""
    next_states: torch.Tensor
    """Of the next states, ``(B, n_actions)``, detached: they choose, they do not learn."""
    boundary: torch.Tensor
    """Of the synthetic boundary rows, ``(M, n_actions)``; ``(0, n_actions)`` without them."""


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
        limit at the speed the network sees (through the speed limiter when
        ``speed_limiter`` is on: a rise it lands on the limit does not exceed it)."""
        c = self.config
        if c.limit_margin is None or c.unsafe_margin is None:
            return c.unsafe_margin
        over_limit = torch.from_numpy(~limit_mask(obs, c.speed_limiter))
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

        Args:
            batch: the minibatch (with ``weights``, prioritised replay's).
            env_steps: transitions collected so far (sets the learning rate).
            boundary: synthetic observations and their safe-action masks, or ``None``.

        Returns:
            What the step did (losses, mean Q, learning rate, gradient norm, priorities).
        """
        c = self.config
        lr = self._anneal_learning_rate(env_steps)
        q = self._online_q(batch, boundary)
        target = self._td_target(batch, q.next_states)
        weights = None if batch.weights is None else torch.from_numpy(batch.weights)
        td = td_loss(q.taken, target, c.loss, c.huber_delta, weights)
        unsafe, on_boundary = self._unsafe_losses(batch, q, boundary)
        grad_norm = self._optimise(self._total_loss(td, unsafe, on_boundary))
        self.updates += 1
        if self.updates % c.target_update_interval == 0:
            self.update_target(c.tau)
        return UpdateStats(
            td_loss=float(td.detach()),
            unsafe_loss=0.0 if unsafe is None else float(unsafe.detach()),
            boundary_loss=0.0 if on_boundary is None else float(on_boundary.detach()),
            q_values=float(q.taken.detach().mean()),
            learning_rate=lr,
            grad_norm=grad_norm,
            abs_td_errors=(None if weights is None else (target - q.taken.detach()).abs().numpy()),
        )

    def _anneal_learning_rate(self, env_steps: int) -> float:
        """Set the optimiser's learning rate to :meth:`learning_rate` of ``env_steps``.

        Args:
            env_steps: transitions collected so far.

        Returns:
            The learning rate set.
        """
        lr = self.learning_rate(env_steps)
        for group in self.optimizer.param_groups:
            group["lr"] = lr
        return lr

    def _online_q(
        self, batch: ReplayBatch, boundary: tuple[np.ndarray, np.ndarray] | None
    ) -> _OnlineQ:
        """Online Q-values of the states, next states and boundary rows, in one forward pass.

        Args:
            batch: the minibatch.
            boundary: synthetic observations and their masks, or ``None``.

        Returns:
            The Q-values, split by what they are of.
        """
        obs = torch.from_numpy(batch.obs)
        next_obs = torch.from_numpy(batch.next_obs)
        extra = [torch.from_numpy(boundary[0])] if boundary is not None else []
        q_all = self.q(torch.cat([obs, next_obs, *extra]))  # one forward pass for all
        n = len(obs)
        q_obs = q_all[:n]
        actions = torch.from_numpy(batch.actions).long()
        return _OnlineQ(
            states=q_obs,
            taken=q_obs.gather(1, actions.unsqueeze(1)).squeeze(1),
            next_states=q_all[n : 2 * n].detach(),
            boundary=q_all[2 * n :],
        )

    def _td_target(self, batch: ReplayBatch, next_q_online: torch.Tensor) -> torch.Tensor:
        """Double-DQN targets: the online net picks the next action, the target net values it.

        With ``safe_learning`` the online net picks among the safe actions of the next state.

        Args:
            batch: the minibatch.
            next_q_online: the online Q-values of its next states, detached.

        Returns:
            Targets of shape ``(B,)``, without gradient.
        """
        with torch.no_grad():
            next_q_target = self.q_target(torch.from_numpy(batch.next_obs))
        next_mask = torch.from_numpy(batch.next_mask) if self.config.safe_learning else None
        return double_dqn_target(
            torch.from_numpy(batch.rewards), torch.from_numpy(batch.terminated), next_q_online,
            next_q_target, torch.from_numpy(batch.discount), next_mask,
        )  # fmt: skip

    def _unsafe_losses(
        self,
        batch: ReplayBatch,
        q: _OnlineQ,
        boundary: tuple[np.ndarray, np.ndarray] | None,
    ) -> tuple[torch.Tensor | None, torch.Tensor | None]:
        """The unsafe-action losses of ``safe_learning``, on the batch and on the boundary rows.

        The batch's states use their stored masks and :meth:`_margins`; the boundary rows
        their own masks and ``boundary_margin`` (:meth:`_margins` if unset).

        Args:
            batch: the minibatch.
            q: the online Q-values of :meth:`_online_q`.
            boundary: synthetic observations and their masks, or ``None``.

        Returns:
            (loss on the batch, loss on the boundary rows); ``None`` for a loss not computed:
            both without ``safe_learning``, the second without ``boundary``.
        """
        c = self.config
        if not c.safe_learning:
            return None, None
        unsafe = unsafe_action_loss(
            q.states, torch.from_numpy(batch.mask), c.unsafe_q, c.loss, c.huber_delta,
            self._margins(batch.obs),
        )  # fmt: skip
        if boundary is None:
            return unsafe, None
        margin = self._margins(boundary[0]) if c.boundary_margin is None else c.boundary_margin
        on_boundary = unsafe_action_loss(
            q.boundary, torch.from_numpy(boundary[1]), c.unsafe_q, c.loss, c.huber_delta, margin
        )
        return unsafe, on_boundary

    def _total_loss(
        self, td: torch.Tensor, unsafe: torch.Tensor | None, on_boundary: torch.Tensor | None
    ) -> torch.Tensor:
        """The loss to minimise: the TD loss plus the weighted unsafe-action losses.

        ``td + unsafe_loss_weight * unsafe + boundary_weight * on_boundary``, leaving out the
        terms not computed (``None``).

        Args:
            td: the TD loss.
            unsafe: the unsafe-action loss on the batch's states.
            on_boundary: the unsafe-action loss on the boundary rows.

        Returns:
            The loss the optimiser minimises.
        """
        c = self.config
        loss = td
        if unsafe is not None:
            loss = loss + c.unsafe_loss_weight * unsafe
        if on_boundary is not None:
            loss = loss + c.boundary_weight * on_boundary
        return loss

    def _optimise(self, loss: torch.Tensor) -> float:
        """One optimiser step on ``loss``, the gradients clipped to ``grad_clip_norm`` if set.

        Args:
            loss: the loss to minimise.

        Returns:
            The gradient norm before clipping; 0 when clipping is off.
        """
        self.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        grad_norm = 0.0
        if self.config.grad_clip_norm is not None:
            grad_norm = float(
                torch.nn.utils.clip_grad_norm_(self.q.parameters(), self.config.grad_clip_norm)
            )
        self.optimizer.step()
        return grad_norm

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
