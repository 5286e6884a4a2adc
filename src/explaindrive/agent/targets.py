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
    gamma: float | Tensor,
    next_mask: Tensor | None = None,
) -> Tensor:
    """Double-DQN bootstrap target ``r + gamma (1 - done) Q_target(s', argmax_a Q_online(s', a))``.

    The online network selects the next action and the target network evaluates it, which
    removes most of the over-estimation of the plain max. ``terminated`` must be true only
    for real terminal states (collision, leaving the route), not for time-limit truncation.
    With ``next_mask`` the argmax runs over the allowed (safe) actions of ``s'`` only, so the
    values of unsafe actions never leak into the targets of safe ones.

    Args:
        rewards: shape ``(B,)`` (for n-step transitions the discounted sum of n rewards).
        terminated: shape ``(B,)``, bool or 0/1.
        next_q_online: online Q-values of the next states, ``(B, n_actions)``.
        next_q_target: target-network Q-values of the next states, ``(B, n_actions)``.
        gamma: discount of the bootstrap, a number or one per transition (gamma^n).
        next_mask: bool ``(B, n_actions)``, the actions the argmax may choose; every row
            must allow at least one.

    Returns:
        Targets of shape ``(B,)`` (no gradient flows through them).
    """
    with torch.no_grad():
        if next_mask is not None:
            next_q_online = next_q_online.masked_fill(~next_mask, float("-inf"))
        best = next_q_online.argmax(dim=-1, keepdim=True)
        bootstrap = next_q_target.gather(-1, best).squeeze(-1)
        not_done = 1.0 - terminated.to(rewards.dtype)
        return rewards + gamma * not_done * bootstrap


def unsafe_action_loss(
    q_values: Tensor,
    mask: Tensor,
    unsafe_q: float,
    kind: str = "mse",
    huber_delta: float = 1.0,
    margin: float | Tensor | None = None,
) -> Tensor:
    """Loss that pushes the Q-value of every unsafe action down to ``unsafe_q``, or, with
    ``margin``, to ``margin`` below the best safe action of its state.

    Only values above that floor are pushed; safe actions (``mask`` true) are untouched.
    The per-state sum over unsafe actions is averaged over the batch. The relative floor
    (a large-margin loss, as in DQfD) keeps every unsafe action below every safe one without
    dragging the values of a state towards a fixed number; a state without a safe action
    falls back to ``unsafe_q``.

    Args:
        q_values: online Q-values, ``(B, n_actions)``.
        mask: bool ``(B, n_actions)``, true for safe actions.
        unsafe_q: the value unsafe actions are pushed to.
        kind: ``mse`` or ``huber``, as :func:`td_loss`.
        huber_delta: threshold of the Huber loss.
        margin: if set, the floor is the best safe Q-value (not differentiated) minus this:
            one number, or one per action of each state, ``(B, n_actions)``.
    """
    floor = torch.full_like(q_values[:, :1], unsafe_q)
    if margin is not None:
        best_safe = q_values.detach().masked_fill(~mask, -torch.inf).max(dim=-1, keepdim=True)
        floor = torch.where(torch.isfinite(best_safe.values), best_safe.values - margin, floor)
    excess = (q_values - floor).clamp(min=0.0) * (~mask).to(q_values.dtype)
    per_action = _elementwise(excess, torch.zeros_like(excess), kind, huber_delta, "loss")
    return per_action.sum(dim=-1).mean()


def _elementwise(pred: Tensor, target: Tensor, kind: str, huber_delta: float, name: str) -> Tensor:
    """The ``mse`` or ``huber`` loss of each element (``name`` labels the error).

    Raises:
        ValueError: if ``kind`` is neither ``mse`` nor ``huber``.
    """
    if kind == "mse":
        return F.mse_loss(pred, target, reduction="none")
    if kind == "huber":
        return F.huber_loss(pred, target, delta=huber_delta, reduction="none")
    raise ValueError(f"unknown {name} {kind!r}; expected 'mse' or 'huber'")


def td_loss(
    q_taken: Tensor,
    target: Tensor,
    kind: str = "mse",
    huber_delta: float = 1.0,
    weights: Tensor | None = None,
) -> Tensor:
    """Mean TD loss between the Q-values of the taken actions and their targets; with
    ``weights`` (importance-sampling weights of prioritised replay), the weighted mean.

    Raises:
        ValueError: if ``kind`` is neither ``mse`` nor ``huber``.
    """
    per_row = _elementwise(q_taken, target, kind, huber_delta, "TD loss")
    return per_row.mean() if weights is None else (weights * per_row).mean()


def linear_schedule(start: float, end: float, duration: int, t: int) -> float:
    """Linear interpolation from ``start`` (t = 0) to ``end`` (t >= duration)."""
    if duration <= 0:
        return end
    frac = min(max(t, 0) / duration, 1.0)
    return start + frac * (end - start)
