"""The driver's estimate of its own speed under a noisy speed sensor.

A driver that reads its speed through Gaussian noise (``--obs-noise``) still knows the speed
change it asked for in each step. :class:`SpeedEstimator` is a one-dimensional Kalman filter
that fuses the two: it predicts the speed from the last estimate and the commanded change,
then corrects the prediction towards the reading in proportion to their uncertainties.

- The prediction's uncertainty grows by :data:`SPEED_DRIFT_MPS` a step (a car does not do
  exactly what it is told: actuator lag, grade, wheel slip). In this simulator the change is
  exact, so the drift is the only reason the estimate follows the readings at all.
- A ride starts at a standstill (the ego departs at 0 m/s), so the first estimate is exact.
- A car whose predicted speed is not above 0 stands: braking does not make it reverse, and a
  standing car knows it stands. The estimate is 0 then and certain; readings, which the sensor
  clips at 0 and so biases upwards there, do not move it.
- A reading more than :data:`GATE_SD` standard deviations of the innovation away from the
  prediction means the car did not do what it was told (a collision, SUMO moving it): the
  estimate restarts from the reading.

Without noise (``sd_mps`` 0) the estimate is the reading. With noise of 0.6 m/s the
estimate's standard deviation settles at about 0.17 m/s (0.21 at 0.9 m/s,
:func:`settled_sd`): 12 and 13 m/s, 1.7 deviations of a reading apart, lie 6 deviations of
the estimate apart.
"""

from __future__ import annotations

import math

from explaindrive.env.actions import limited_change, speed_change

SPEED_DRIFT_MPS = 0.05
"""[m/s] Standard deviation of the difference, per 1 s step, between the speed the car was
told to reach and the speed it reaches (the filter's process noise)."""

GATE_SD = 5.0
"""Innovations beyond this many standard deviations restart the estimate from the reading."""


class SpeedEstimator:
    """Kalman filter on the ego speed (see the module docstring).

    Args:
        sd_mps: standard deviation of the speed sensor's noise [m/s]; 0: no filtering.
        drift_mps: the filter's process noise per step [m/s].
        start_mps: the speed at the start of the ride, if known (a ride starts at rest);
            ``None``: the first reading starts the estimate, with the sensor's uncertainty.

    Raises:
        ValueError: if ``sd_mps`` or ``drift_mps`` is negative or not finite.
    """

    def __init__(
        self,
        sd_mps: float,
        drift_mps: float = SPEED_DRIFT_MPS,
        start_mps: float | None = 0.0,
    ) -> None:
        for name, value in (("sd_mps", sd_mps), ("drift_mps", drift_mps)):
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        self.sd_mps = float(sd_mps)
        self.drift_mps = float(drift_mps)
        self.speed_mps: float | None = None if start_mps is None else max(0.0, float(start_mps))
        self.variance = 0.0
        """Variance of the estimate [(m/s)^2]."""
        self.restarts = 0
        """Readings that restarted the estimate (beyond :data:`GATE_SD`)."""

    def update(self, reading_mps: float, change_mps: float | None) -> float:
        """The estimate after a step that asked for ``change_mps`` and read ``reading_mps``.

        ``change_mps`` is ``None`` before the first action (the reading at the reset).
        """
        reading = float(reading_mps)
        noise_var = self.sd_mps**2
        if noise_var == 0.0:
            self.speed_mps, self.variance = reading, 0.0
            return reading
        if self.speed_mps is None:
            self.speed_mps, self.variance = reading, noise_var
            return reading
        predicted = self.speed_mps + (change_mps or 0.0)
        if predicted <= 0.0:  # standing: certain, whatever the clipped reading says
            self.speed_mps, self.variance = 0.0, 0.0
            return 0.0
        predicted_var = self.variance + self.drift_mps**2
        innovation = reading - predicted
        if abs(innovation) > GATE_SD * math.sqrt(predicted_var + noise_var):
            self.restarts += 1
            self.speed_mps, self.variance = reading, noise_var
            return reading
        gain = predicted_var / (predicted_var + noise_var)
        self.speed_mps = predicted + gain * innovation
        self.variance = (1.0 - gain) * predicted_var
        return self.speed_mps


def settled_sd(sd_mps: float, drift_mps: float = SPEED_DRIFT_MPS) -> float:
    """[m/s] The standard deviation at which the estimate's error settles on a sensor with
    noise ``sd_mps`` (the steady state of the filter's Riccati equation: the prediction's
    variance p = (q + sqrt(q^2 + 4 q r)) / 2 with q = drift^2, r = sd^2, then p r / (p + r)
    after the reading)."""
    q, r = drift_mps**2, sd_mps**2
    if r == 0.0:
        return 0.0
    p = (q + math.sqrt(q * q + 4.0 * q * r)) / 2.0
    return math.sqrt(p * r / (p + r))


def commanded_change(speed_mps: float, action: int, limit_mps: float, speed_limiter: bool) -> float:
    """The speed change [m/s] the car commands with ``action`` at the speed it knows, which
    the estimate predicts with: the action's change, through the speed limiter under the
    posted limit ``limit_mps`` when the car has one (+1 at 13 m/s under 13.89 m/s: 0.89)."""
    return limited_change(speed_mps, speed_change(action), limit_mps if speed_limiter else None)
