"""Pure tensor functions of D3QN: dueling aggregation, double-DQN target, TD loss.

Kept free of modules and state so that each can be checked against numbers computed by
hand (``tests/agent/test_targets.py``).
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import Tensor


def dueling_aggregate(value: Tensor, advantage: Tensor) -> Tensor:
    """Combine the dueling streams: ``Q = V + A - mean_a A``.

    Args:
        value: state values, shape ``(B, 1)`` or ``(B,)``.
        advantage: advantages, shape ``(B, n_actions)``.

    Returns:
        Q-values of shape ``(B, n_actions)``.
    """
    if value.dim() == advantage.dim() - 1:
        value = value.unsqueeze(-1)
    return value + advantage - advantage.mean(dim=-1, keepdim=True)


def double_dqn_target(
    rewards: Tensor,
    terminated: Tensor,
    next_q_online: Tensor,
    next_q_target: Tensor,
    gamma: float,
) -> Tensor:
    """Double-DQN bootstrap target ``r + gamma (1 - done) Q_target(s', argmax_a Q_online(s', a))``.

    The online network selects the next action and the target network evaluates it, which
    removes most of the over-estimation of the plain max. ``terminated`` must be true only
    for real terminal states (collision, leaving the route), not for time-limit truncation.

    Args:
        rewards: shape ``(B,)``.
        terminated: shape ``(B,)``, bool or 0/1.
        next_q_online: online Q-values of the next states, ``(B, n_actions)``.
        next_q_target: target-network Q-values of the next states, ``(B, n_actions)``.
        gamma: discount factor.

    Returns:
        Targets of shape ``(B,)`` (no gradient flows through them).
    """
    with torch.no_grad():
        best = next_q_online.argmax(dim=-1, keepdim=True)
        bootstrap = next_q_target.gather(-1, best).squeeze(-1)
        not_done = 1.0 - terminated.to(rewards.dtype)
        return rewards + gamma * not_done * bootstrap


def td_loss(q_taken: Tensor, target: Tensor, kind: str = "mse", huber_delta: float = 1.0) -> Tensor:
    """Mean TD loss between the Q-values of the taken actions and their targets.

    Raises:
        ValueError: if ``kind`` is neither ``mse`` nor ``huber``.
    """
    if kind == "mse":
        return F.mse_loss(q_taken, target)
    if kind == "huber":
        return F.huber_loss(q_taken, target, delta=huber_delta)
    raise ValueError(f"unknown TD loss {kind!r}; expected 'mse' or 'huber'")


def linear_schedule(start: float, end: float, duration: int, t: int) -> float:
    """Linear interpolation from ``start`` (t = 0) to ``end`` (t >= duration)."""
    if duration <= 0:
        return end
    frac = min(max(t, 0) / duration, 1.0)
    return start + frac * (end - start)
