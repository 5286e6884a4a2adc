"""Network, learner updates, target updates and action selection."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from explaindrive.agent.buffer import ReplayBatch, ReplayBuffer
from explaindrive.agent.config import PAPER, PASSENGER
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.network import DuelingQNetwork
from explaindrive.agent.shield import training_mask
from explaindrive.agent.targets import dueling_aggregate
from explaindrive.config import ConfigError
from explaindrive.env.safety import limit_mask
from explaindrive.env.state import normalize


def test_network_normalises_raw_observations_itself() -> None:
    torch.manual_seed(0)
    net = DuelingQNetwork((16, 16))
    raw = np.array([[1, 8.0, 13.9, 45.0, -2.0, 120.0, 2, 200.0]], dtype=np.float32)
    features = net.trunk(torch.from_numpy(normalize(raw)))
    manual = dueling_aggregate(net.value(features), net.advantage(features))
    assert torch.allclose(net(torch.from_numpy(raw)), manual)
    assert net(torch.from_numpy(raw)).shape == (1, 7)
    assert int(net.greedy(raw[0])) == int(manual.argmax())
    with pytest.raises(ValueError, match="hidden_sizes"):
        DuelingQNetwork((0,))


def test_near_range_features_read_each_distance_by_hand() -> None:
    net = DuelingQNetwork((1,), near_range_m=10.0)
    assert net.trunk[0].in_features == 11  # 8 scaled components, then d_lead, d_tl, d_cross
    with torch.no_grad():
        for p in net.parameters():
            p.zero_()
        net.trunk[0].weight[0, 9] = 1.0  # d_tl's feature
        net.value.weight.fill_(1.0)
    raw = np.array([[1, 0.0, 13.9, 10.0, 0.0, 10.0, 2, 200.0]], dtype=np.float32)
    # Q = value = relu(exp(-10 / 10)) = 0.367879 for every action (no advantage)
    q = net(torch.from_numpy(raw)).detach().numpy()
    assert q == pytest.approx(np.full((1, 7), 0.367879), abs=1e-6)
    raw[0, 5] = 5.0  # half the range: exp(-0.5) = 0.606531
    assert net(torch.from_numpy(raw))[0, 0].item() == pytest.approx(0.606531, abs=1e-6)
    with torch.no_grad():
        net.trunk[0].weight[0, 9] = 0.0
        net.trunk[0].weight[0, 10] = 1.0  # d_cross's: exp(-200 / 10) = 2.1e-9, nothing seen
    assert net(torch.from_numpy(raw))[0, 0].item() == pytest.approx(2.06e-9, rel=1e-2)
    with pytest.raises(ValueError, match="near_range_m"):
        DuelingQNetwork((4,), near_range_m=0.0)


def test_learner_builds_the_network_the_config_names() -> None:
    assert D3QNLearner(PAPER.replace(hidden_sizes=[4])).q.trunk[0].in_features == 8
    learner = D3QNLearner(PAPER.replace(hidden_sizes=[4], near_range_m=15.0))
    assert learner.q.near_range_m == learner.q_target.near_range_m == 15.0
    assert learner.q.trunk[0].in_features == 11


def test_soft_and_hard_target_updates() -> None:
    learner = D3QNLearner(PAPER.replace(hidden_sizes=[4]))
    with torch.no_grad():
        for p in learner.q.parameters():
            p.fill_(1.0)
        for p in learner.q_target.parameters():
            p.fill_(0.0)
    learner.update_target(0.1)
    learner.update_target(0.1)  # 0.1, then 0.9 * 0.1 + 0.1 = 0.19
    assert all(torch.allclose(p, torch.full_like(p, 0.19)) for p in learner.q_target.parameters())
    learner.update_target(1.0)
    assert all(torch.equal(p, torch.ones_like(p)) for p in learner.q_target.parameters())


def test_epsilon_greedy_batch() -> None:
    learner = D3QNLearner(PAPER.replace(eps_start=1.0, eps_end=0.1, eps_decay_steps=100))
    assert learner.epsilon(50) == pytest.approx(0.55)
    obs = np.zeros((500, 8), dtype=np.float32)
    rng = np.random.default_rng(0)
    greedy = learner.act(obs, 0.0, rng)
    assert len(set(greedy.tolist())) == 1  # same state -> same greedy action
    random = learner.act(obs, 1.0, rng)
    assert set(random.tolist()) == set(range(7))


def test_masked_exploration_keeps_allowed_actions() -> None:
    learner = D3QNLearner(PAPER.replace(hidden_sizes=[4]))
    with torch.no_grad():
        for p in learner.q.parameters():
            p.zero_()
        learner.q.advantage.bias.copy_(torch.arange(7.0))  # greedy: +3 m/s
    # 10 m/s towards a red light 30 m ahead: +2 and +3 cannot stop in time; +1 can
    # (11 + 8 + 5 + 2 + 2 = 28 <= 30), so the mask keeps the best allowed action, +1.
    red = np.tile(np.array([0, 10.0, 13.89, 30.0, 10.0, 30.0, 2, 200.0], np.float32), (300, 1))
    mask = training_mask(red)
    rng = np.random.default_rng(0)
    assert set(learner.act(red, 0.0, rng, mask).tolist()) == {4}
    explored = learner.act(red, 1.0, rng, mask)  # random actions, forbidden ones replaced
    assert set(explored.tolist()) == {0, 1, 2, 3, 4}
    assert set(learner.act(red, 0.0, rng).tolist()) == {6}  # no mask: the bare choice


def test_safe_learning_pushes_unsafe_actions_down_and_masks_the_target() -> None:
    cfg = PAPER.replace(hidden_sizes=[16], lr=1e-2, safe_learning=True, unsafe_q=-5.0,
                        target_update_interval=1, batch_size=32)  # fmt: skip
    learner = D3QNLearner(cfg)
    obs = np.tile(np.array([0, 10.0, 13.89, 30.0, 10.0, 30.0, 2, 200.0], np.float32), (32, 1))
    mask = training_mask(obs)  # +2, +3 unsafe
    batch = ReplayBatch(
        obs=obs, actions=np.full(32, 3), rewards=np.ones(32, np.float32), next_obs=obs,
        terminated=np.ones(32, bool), discount=np.full(32, 0.99, np.float32), mask=mask,
        next_mask=mask,
    )  # fmt: skip
    for _ in range(300):
        stats = learner.update(batch, 0)
    q = learner.q_values(obs[:1])[0]
    assert q[5] < -4.5 and q[6] < -4.5  # pushed down to the floor (or below: one-sided)
    assert q[3] == pytest.approx(1.0, abs=0.1)  # the taken action's terminal reward
    assert stats.unsafe_loss < 0.1


def test_epsilon_drops_to_its_final_value() -> None:
    learner = D3QNLearner(PAPER.replace(eps_start=1.0, eps_end=0.05, eps_decay_steps=100,
                                        eps_final=0.01, eps_final_after=200))  # fmt: skip
    assert [learner.epsilon(t) for t in (0, 100, 199, 200)] == pytest.approx(
        [1.0, 0.05, 0.05, 0.01]
    )


def test_learning_rate_schedule() -> None:
    learner = D3QNLearner(PAPER.replace(lr=1e-3, lr_final=1e-4, lr_decay_steps=1000))
    assert learner.learning_rate(500) == pytest.approx(5.5e-4)
    assert D3QNLearner(PAPER).learning_rate(10**9) == pytest.approx(1e-3)


def test_learner_learns_a_contextual_bandit() -> None:
    """Reward 1 for action 6 only, every transition terminal: greedy must become 6."""
    cfg = PAPER.replace(hidden_sizes=[32, 32], lr=1e-2, batch_size=64, target_update_interval=10)
    learner = D3QNLearner(cfg)
    rng = np.random.default_rng(0)
    buf = ReplayBuffer(2000)
    obs = rng.uniform(0, 1, (2000, 8)).astype(np.float32) * np.float32(20)
    actions = rng.integers(0, 7, 2000)
    buf.add(obs, actions, (actions == 6).astype(np.float32), obs, np.ones(2000, bool), 0.99)
    losses = [learner.update(buf.sample(64, rng), 0).td_loss for _ in range(300)]
    assert np.mean(losses[-20:]) < 0.1 * np.mean(losses[:20])
    assert (learner.act(obs[:100], 0.0, rng) == 6).all()
    assert learner.updates == 300


@pytest.mark.parametrize(
    ("limit_margin", "speed_limiter"), [(None, False), (5.0, False), (5.0, True)]
)
def test_actions_over_the_limit_have_their_own_margin(
    limit_margin: float | None, speed_limiter: bool
) -> None:
    # Comfort at 12 m/s in the 13.89 m/s zone, a red line 35 m ahead: -3..0 are safe, +1
    # (13 m/s) is unsafe for the light alone (standing after it needs 13 + 22 + 2 = 37 m),
    # +2 and +3 also exceed the limit without the limiter (14 and 15 m/s); with it they
    # land on 13.89 m/s (standing then needs 13.89 + 25.56 + 2 = 41.45 m) and exceed
    # nothing. The loss is the summed squared excess of the unsafe values over
    # (best safe - margin), by hand from the values before the update: 30 for +1, and for
    # +2 and +3 limit_margin (30 unless set) without the limiter, 30 with it.
    config = PASSENGER.replace(loss="mse", limit_margin=limit_margin, speed_limiter=speed_limiter)
    learner = D3QNLearner(config)
    row = np.asarray([[1.0, 12.0, 13.89, 35.0, 12.0, 35.0, 2.0, 200.0]], dtype=np.float32)
    mask = training_mask(row, True, speed_limiter)
    assert mask[0].tolist() == [True] * 4 + [False] * 3
    over = [False] * 5 + [not speed_limiter] * 2
    assert (~limit_mask(row, speed_limiter))[0].tolist() == over
    q = learner.q_values(row)[0].astype(np.float64)
    best = q[:4].max()
    over_margin = 30.0 if speed_limiter else (limit_margin or 30.0)
    floors = best - np.array([30.0, over_margin, over_margin])
    expected = float(np.sum(np.maximum(q[4:] - floors, 0.0) ** 2))
    batch = ReplayBatch(
        obs=row, actions=np.array([0]), rewards=np.zeros(1, np.float32), next_obs=row,
        terminated=np.ones(1, bool), discount=np.ones(1, np.float32),
        mask=mask, next_mask=mask,
    )  # fmt: skip
    assert learner.update(batch, 0).unsafe_loss == pytest.approx(expected, rel=1e-4)


def test_the_limit_margin_reads_the_limiter() -> None:
    # +1 at 13 m/s under 13.89: 14 m/s without the limiter (over), 13.89 with it (not over);
    # at 15 m/s -1 leaves 14 and the limiter slows 0..+3 to 14 (over); -3 and -2 are not
    at_13 = np.asarray([[0.0, 13.0, 13.89, 200.0, 0.0, 200.0, 0.0, 200.0]], dtype=np.float32)
    assert limit_mask(at_13)[0].tolist() == [True] * 4 + [False] * 3
    assert limit_mask(at_13, speed_limiter=True)[0].tolist() == [True] * 7
    at_15 = at_13.copy()
    at_15[0, 1] = 15.0
    assert limit_mask(at_15, speed_limiter=True)[0].tolist() == [True] * 2 + [False] * 5
    margins = D3QNLearner(PASSENGER.replace(limit_margin=5.0))._margins(np.vstack([at_13, at_15]))
    assert isinstance(margins, torch.Tensor)
    assert margins.tolist() == [[30.0] * 7, [30.0] * 2 + [5.0] * 5]


def test_limit_margin_needs_unsafe_margin() -> None:
    with pytest.raises(ConfigError, match="limit_margin needs unsafe_margin"):
        PAPER.replace(limit_margin=5.0)


def test_best_actions_by_hand() -> None:
    q = np.array([[0.0, 5.0, 1.0, 0, 0, 0, 9.0], [3.0, 2.0, 1.0, 0, 0, 0, 0]], dtype=np.float32)
    assert D3QNLearner.best_actions(q).tolist() == [6, 0]
    mask = np.ones((2, 7), bool)
    mask[0, 6] = mask[1, 0] = False
    assert D3QNLearner.best_actions(q, mask).tolist() == [1, 1]


def test_the_loss_weighs_its_terms_by_hand() -> None:
    # td 1, unsafe 2, boundary 3 with weights 0.5 and 0.25: 1 + 0.5 * 2 + 0.25 * 3 = 2.75;
    # a term not computed (None) is left out, not counted as 0 times its weight.
    learner = D3QNLearner(PAPER.replace(unsafe_loss_weight=0.5, boundary_weight=0.25))
    td, unsafe, on_boundary = torch.tensor(1.0), torch.tensor(2.0), torch.tensor(3.0)
    assert float(learner._total_loss(td, unsafe, on_boundary)) == 2.75
    assert float(learner._total_loss(td, unsafe, None)) == 2.0
    assert learner._total_loss(td, None, None) is td
