"""The driver's speed estimate under a noisy speed sensor: the Kalman filter by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from explaindrive.agent.estimator import GATE_SD, SpeedEstimator, commanded_change, settled_sd


def test_without_noise_the_estimate_is_the_reading() -> None:
    est = SpeedEstimator(0.0)
    assert est.update(3.7, None) == 3.7
    assert est.update(9.2, 1) == 9.2 and est.variance == 0.0


def test_a_ride_starts_at_rest_and_a_standing_car_stays_certain() -> None:
    est = SpeedEstimator(0.6)
    assert est.update(0.4, None) == 0.0  # the clipped reading at the start does not move it
    assert est.update(0.9, 0) == 0.0 and est.variance == 0.0
    est.speed_mps = 2.1
    assert est.update(0.5, -3) == 0.0  # braked below 0: standing


def test_one_correction_by_hand() -> None:
    est = SpeedEstimator(0.6, drift_mps=0.05)
    est.update(0.3, None)
    # predicted 3, variance 0 + 0.05^2 = 0.0025; gain 0.0025 / (0.0025 + 0.36) = 0.0068966
    assert est.update(3.6, 3) == pytest.approx(3.0 + 0.0068966 * 0.6, abs=1e-6)
    assert est.variance == pytest.approx((1 - 0.0068966) * 0.0025, rel=1e-5)


def test_an_unknown_start_takes_the_first_reading_with_the_sensor_s_variance() -> None:
    est = SpeedEstimator(0.6, start_mps=None)
    assert est.update(7.3, None) == 7.3 and est.variance == pytest.approx(0.36)


def test_a_reading_beyond_the_gate_restarts_from_it() -> None:
    est = SpeedEstimator(0.6, drift_mps=0.05, start_mps=10.0)
    # the innovation's sd: sqrt(0.0025 + 0.36) = 0.60208; the gate at 5 sd is 3.0104 m/s
    assert GATE_SD == 5.0
    assert est.update(13.0, 0) == pytest.approx(10.0 + 3.0 * 0.0068966, abs=1e-6)
    est = SpeedEstimator(0.6, drift_mps=0.05, start_mps=10.0)
    assert est.update(14.0, 0) == 14.0
    assert est.variance == pytest.approx(0.36) and est.restarts == 1


@pytest.mark.parametrize(("sd", "settled"), [(0.6, 0.1696), (0.9, 0.2093)])
def test_the_estimate_s_deviation_settles_where_the_riccati_equation_puts_it(
    sd: float, settled: float
) -> None:
    # steady state: p = (q + sqrt(q^2 + 4 q r)) / 2 before the reading, p r / (p + r) after;
    # q = 0.05^2, r = sd^2: 0.6 -> 0.02877 (sd 0.1696), 0.9 -> 0.04381 (sd 0.2093)
    est = SpeedEstimator(sd, start_mps=10.0)
    for _ in range(500):
        est.update(est.speed_mps or 0.0, 0)
    assert math.sqrt(est.variance) == pytest.approx(settled, abs=5e-4)
    assert settled_sd(sd) == pytest.approx(settled, abs=5e-4) and settled_sd(0.0) == 0.0


def test_on_a_noisy_sensor_the_estimate_is_closer_than_the_readings() -> None:
    rng = np.random.default_rng(7)
    est = SpeedEstimator(0.6)
    true, errors, readings = 0.0, [], []
    changes = [3, 3, 3, 2, 1] + [0] * 200 + [-1, -2, 1] + [0] * 100
    est.update(0.0, None)
    for change in changes:
        true = max(0.0, true + change)
        reading = max(0.0, true + 0.6 * rng.standard_normal())
        errors.append(est.update(reading, change) - true)
        readings.append(reading - true)
    assert np.std(readings) > 0.55
    assert np.std(errors) < 0.2 and abs(np.mean(errors)) < 0.15 and est.restarts == 0


@pytest.mark.parametrize(("sd", "drift"), [(-0.1, 0.05), (0.6, float("nan"))])
def test_bad_deviations_are_refused(sd: float, drift: float) -> None:
    with pytest.raises(ValueError, match="finite number >= 0"):
        SpeedEstimator(sd, drift_mps=drift)


@pytest.mark.parametrize(
    ("speed", "action", "limiter", "change"),
    [
        (13.0, 4, True, 13.89 - 13.0),  # +1 under 13.89: the limiter lets 0.89 through
        (13.0, 4, False, 1.0),  # without it, the whole +1
        (15.0, 3, True, -1.0),  # a keep above the limit coasts by 1 m/s
        (15.0, 3, False, 0.0),
        (10.0, 6, True, 3.0),  # +3 from 10 stays under the limit
        (1.0, 0, True, -3.0),  # -3 from 1 m/s: the estimate, not the change, stops at 0
    ],
)
def test_the_commanded_change_goes_through_the_cars_limiter(speed, action, limiter, change):
    assert commanded_change(speed, action, 13.89, limiter) == pytest.approx(change)
