import numpy as np
import pytest

from explaindrive.env import state as S
from explaindrive.env.noise import ObservationNoise, noisy_rows, parse_noise

OBS = np.array([0.0, 10.0, 13.89, 40.0, 2.0, 200.0, 2.0, 0.5], dtype=np.float32)


def test_noise_moves_distances_and_speeds_only():
    draws = np.random.default_rng(3).standard_normal(5)
    seen = ObservationNoise(2.0, 0.5).apply(OBS, np.random.default_rng(3))
    assert seen[S.D_LEAD] == pytest.approx(40.0 + 2.0 * draws[0], abs=1e-5)
    assert seen[S.D_TL] == 200.0  # nothing detected stays nothing detected
    assert seen[S.D_CROSS] == pytest.approx(max(0.5 + 2.0 * draws[2], 0.0), abs=1e-5)
    assert seen[S.V_EGO] == pytest.approx(10.0 + 0.5 * draws[3], abs=1e-5)
    assert seen[S.DV] == pytest.approx(2.0 + 0.5 * draws[4], abs=1e-5)
    assert (seen[S.CMD], seen[S.V_LIM], seen[S.TLS]) == (0.0, pytest.approx(13.89), 2.0)
    assert OBS[S.D_LEAD] == 40.0  # the input is left alone


def test_noise_is_clipped_to_the_state_bounds():
    obs = OBS.copy()
    obs[S.V_EGO] = 0.0
    seen = ObservationNoise(20.0, 5.0).apply(obs, np.random.default_rng(0))
    assert np.all(seen >= S.STATE_LOW) and np.all(seen <= S.STATE_HIGH)


def test_no_noise_is_the_identity():
    seen = ObservationNoise().apply(OBS, np.random.default_rng(0))
    assert not ObservationNoise().active
    np.testing.assert_array_equal(seen, OBS)


def test_rows_draw_what_one_observation_draws():
    one = ObservationNoise(2.0, 0.5).apply(OBS, np.random.default_rng(3))
    rows = noisy_rows(OBS[None], np.array([2.0]), np.array([0.5]), np.random.default_rng(3))
    np.testing.assert_array_equal(rows[0], one)


def test_each_row_has_its_own_deviations():
    obs = np.repeat(OBS[None], 3, axis=0)
    rows = noisy_rows(obs, np.array([0.0, 2.0, 0.0]), np.array([0.0, 0.0, 0.5]),
                      np.random.default_rng(5))  # fmt: skip
    draws = np.random.default_rng(5).standard_normal((3, 5))
    np.testing.assert_array_equal(rows[0], OBS)  # no noise: unchanged
    assert rows[1, S.D_LEAD] == pytest.approx(40.0 + 2.0 * draws[1, 0], abs=1e-5)
    assert rows[1, S.V_EGO] == 10.0 and rows[2, S.D_LEAD] == 40.0
    assert rows[2, S.V_EGO] == pytest.approx(10.0 + 0.5 * draws[2, 3], abs=1e-5)
    assert rows[2, S.DV] == pytest.approx(2.0 + 0.5 * draws[2, 4], abs=1e-5)
    assert np.all(rows[:, S.D_TL] == 200.0)


def test_parse_noise():
    assert parse_noise("2,0.6") == ObservationNoise(2.0, 0.6)
    with pytest.raises(ValueError, match="SD_M,SD_MPS"):
        parse_noise("2")
    with pytest.raises(ValueError, match=r"distance noise must be in \[0, 20.0\] m"):
        parse_noise("-1,0.3")
    with pytest.raises(ValueError, match="speed noise"):
        parse_noise("1,9")
