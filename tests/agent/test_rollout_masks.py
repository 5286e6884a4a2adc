"""The masks learning uses when the network sees a noisy observation."""

from __future__ import annotations

import numpy as np

from explaindrive.agent.rollout import learning_mask
from explaindrive.agent.shield import training_mask


def _obs(v_mps: float) -> np.ndarray:
    # comfort, limit 8.33 m/s, nothing ahead
    return np.array([1.0, v_mps, 8.33, 200.0, 0.0, 200.0, 0.0, 200.0], dtype=np.float32)


def test_a_car_that_sees_itself_over_the_limit_learns_to_slow_down() -> None:
    seen, true = _obs(10.0), _obs(8.0)
    # true 8 m/s: -3..0 keep within 8.33 (5, 6, 7, 8 m/s), +1..+3 do not
    assert training_mask(true).tolist() == [True] * 4 + [False] * 3
    # seen 10 m/s: only -3 and -2 (7 and 8 m/s) are within 8.33 as it sees it
    assert learning_mask(seen, true, True).tolist() == [True, True] + [False] * 5


def test_without_noise_it_is_the_training_mask() -> None:
    obs = _obs(8.0)
    np.testing.assert_array_equal(learning_mask(obs, obs, True), training_mask(obs))


def test_if_nothing_is_left_the_true_state_decides() -> None:
    # a yellow light 5 m ahead at a true 12 m/s: no braking stops before the line, so with
    # dilemma braking forbidden only keeping the speed (12) or +1 (13 <= 13.89) is allowed;
    # seeing 15 m/s, the limit rule allows only -3 and -2 (12, 13 m/s): nothing in common
    true = np.array([0.0, 12.0, 13.89, 5.0, 12.0, 5.0, 1.0, 200.0], dtype=np.float32)
    seen = true.copy()
    seen[1] = 15.0
    assert training_mask(true, False).tolist() == [False] * 3 + [True, True] + [False] * 2
    assert learning_mask(seen, true, False).tolist() == training_mask(true, False).tolist()
