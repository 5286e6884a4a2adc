"""The pure D3QN functions against numbers computed by hand."""

from __future__ import annotations

import pytest
import torch

from explaindrive.agent.targets import (
    double_dqn_target,
    dueling_aggregate,
    linear_schedule,
    td_loss,
    unsafe_action_loss,
)


def test_dueling_aggregate_subtracts_the_mean_advantage() -> None:
    value = torch.tensor([[1.0], [-2.0]])
    adv = torch.tensor([[1.0, 2.0, 3.0], [0.0, 0.0, 6.0]])
    # mean advantages 2 and 2: Q = V + A - 2
    expected = torch.tensor([[0.0, 1.0, 2.0], [-4.0, -4.0, 2.0]])
    assert torch.equal(dueling_aggregate(value, adv), expected)
    assert torch.equal(dueling_aggregate(value.squeeze(1), adv), expected)


def test_double_dqn_target_selects_online_and_evaluates_target() -> None:
    rewards = torch.tensor([1.0, 0.5, -1.0])
    terminated = torch.tensor([False, True, False])
    next_online = torch.tensor([[1.0, 3.0, 2.0], [5.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    next_target = torch.tensor([[10.0, 20.0, 30.0], [7.0, 8.0, 9.0], [4.0, 5.0, 6.0]])
    target = double_dqn_target(rewards, terminated, next_online, next_target, gamma=0.9)
    # argmax online = (1, 0, 2) -> target Q (20, 7, 6); the second is terminal.
    assert torch.allclose(target, torch.tensor([1.0 + 0.9 * 20.0, 0.5, -1.0 + 0.9 * 6.0]))
    # the plain DQN max over the target net would give 1 + 0.9 * 30 for the first one
    assert target[0].item() != pytest.approx(28.0)


def test_masked_double_dqn_target_chooses_among_safe_actions() -> None:
    next_online = torch.tensor([[1.0, 3.0, 2.0], [5.0, 0.0, 0.0]])
    next_target = torch.tensor([[10.0, 20.0, 30.0], [7.0, 8.0, 9.0]])
    mask = torch.tensor([[True, False, True], [False, True, True]])
    gamma = torch.tensor([0.5, 0.25])  # per transition, e.g. gamma^n of n-step returns
    target = double_dqn_target(
        torch.zeros(2), torch.zeros(2), next_online, next_target, gamma, mask
    )
    # safe argmax online = (2, 1) (the unmasked ones would be 1 and 0) -> target Q (30, 8)
    assert torch.allclose(target, torch.tensor([0.5 * 30.0, 0.25 * 8.0]))


def test_unsafe_action_loss_pushes_only_unsafe_values_above_the_floor() -> None:
    q = torch.tensor([[5.0, -20.0, 0.0], [1.0, 2.0, 3.0]])
    mask = torch.tensor([[False, False, True], [True, True, False]])
    # row 0: (5 - -10)^2 = 225, -20 is below the floor: 0; row 1: (3 + 10)^2 = 169
    assert unsafe_action_loss(q, mask, -10.0, "mse").item() == pytest.approx((225 + 169) / 2)
    # huber, delta 1: 15 - 0.5 and 13 - 0.5
    assert unsafe_action_loss(q, mask, -10.0, "huber").item() == pytest.approx((14.5 + 12.5) / 2)
    assert unsafe_action_loss(q, torch.ones(2, 3, dtype=torch.bool), -10.0).item() == 0.0
    with pytest.raises(ValueError, match="unknown loss"):
        unsafe_action_loss(q, mask, 0.0, "l1")


def test_double_dqn_target_has_no_gradient() -> None:
    online = torch.ones(2, 3, requires_grad=True)
    target = double_dqn_target(torch.zeros(2), torch.zeros(2), online, online * 2, 0.99)
    assert not target.requires_grad


def test_td_losses() -> None:
    q = torch.tensor([1.0, 2.0])
    y = torch.tensor([0.0, 5.0])
    assert td_loss(q, y, "mse").item() == pytest.approx((1.0 + 9.0) / 2)
    # huber, delta 1: 0.5 * 1^2 and 1 * (3 - 0.5)
    assert td_loss(q, y, "huber", 1.0).item() == pytest.approx((0.5 + 2.5) / 2)
    with pytest.raises(ValueError, match="unknown TD loss"):
        td_loss(q, y, "l1")


def test_linear_schedule() -> None:
    assert linear_schedule(1.0, 0.1, 100, 0) == pytest.approx(1.0)
    assert linear_schedule(1.0, 0.1, 100, 50) == pytest.approx(0.55)
    assert linear_schedule(1.0, 0.1, 100, 500) == pytest.approx(0.1)


def test_the_unsafe_loss_with_a_margin_pushes_below_the_best_safe_action() -> None:
    q = torch.tensor([[5.0, 3.0, 8.0, -9.0], [1.0, 2.0, 3.0, 4.0]])
    mask = torch.tensor([[True, False, False, False], [False, False, False, False]])
    # row 0: floor 5 - 10 = -5: excess 8, 13 and 0 -> 64 + 169 = 233
    # row 1: no safe action, floor -100: excess 101..104 -> 10201 + 10404 + 10609 + 10816
    loss = unsafe_action_loss(q, mask, unsafe_q=-100.0, margin=10.0)
    assert float(loss) == pytest.approx((233 + 10201 + 10404 + 10609 + 10816) / 2)
    # the floor is not differentiated: only the unsafe values get a gradient
    q.requires_grad_(True)
    unsafe_action_loss(q, mask, unsafe_q=-100.0, margin=10.0).backward()
    assert q.grad is not None and float(q.grad[0, 0]) == 0.0


def test_the_unsafe_loss_takes_one_margin_per_action() -> None:
    q = torch.tensor([[5.0, 3.0, 8.0, -9.0]])
    mask = torch.tensor([[True, False, False, False]])
    margins = torch.tensor([[10.0, 10.0, 2.0, 2.0]])
    # floors 5 - 10 = -5 for action 1 and 5 - 2 = 3 for actions 2 and 3: excess 8, 5 and 0
    loss = unsafe_action_loss(q, mask, unsafe_q=-100.0, margin=margins)
    assert float(loss) == pytest.approx(64 + 25)
