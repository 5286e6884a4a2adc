"""Synthetic observations near the safety boundary, for the unsafe-action loss.

Safe learning (``docs/agent.md``) teaches the network the shield's rule on the states it
visits. While it acts through the shield, it rarely stands where only the hardest braking
is still safe: the shield braked earlier. Acting on its own later, a network that eases
off by 1 m/s per step towards a red light drifts into exactly those states and finds its
values there untrained; it runs the light.

The rule is a known function of the observation (:func:`~explaindrive.env.safety.
training_mask`), so it can be taught on states nobody drove through. Each minibatch row
yields one synthetic observation:

- its speed moves by a whole -2 ... +2 m/s (kept within [0, 20]); a leader keeps its
  speed, so the closing speed moves with it;
- the nearest object in range (leader, stop line, busy crossing) is moved to a distance
  drawn uniformly between 0 and ``BOUNDARY_SPAN`` times what the car would need to stop
  after accelerating hardest from the new speed (the span where each action's safety
  changes), and every other distance in range is scaled by the same factor (so
  a stop line that was the leader stays the leader);
- a row with nothing in range gets, in half the cases, a red light at such a distance, as
  its leader.

The masks of these rows are computed by the same rule (through the speed limiter when the
config's ``speed_limiter`` is on, as the masks of the episodes' rows are); the learner
pushes their unsafe actions below their best safe one
(:func:`~explaindrive.agent.targets.unsafe_action_loss`), weighted by ``boundary_weight``.
Nothing else is learned from them: they have no reward.

With ``boundary_noise`` the network sees each synthetic row through observation noise
(:func:`~explaindrive.env.noise.noisy_rows`) drawn as the episodes draw theirs: a share
``noisy_share`` of the rows gets deviations uniform between 0 and ``obs_noise_max``. Its mask
stays that of the noise-free row. The episodes teach a noisy view only where the car drove
(a network that keeps 1 m/s under the limit is seldom at the limit, so it seldom learns that
a low reading may be the limit); these rows straddle every boundary, so the network learns
which actions may be unsafe for what it sees.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from explaindrive.agent.shield import training_mask
from explaindrive.env import state as S
from explaindrive.env.actions import SPEED_CHANGES_MPS, stopping_needs
from explaindrive.env.noise import noisy_rows

BOUNDARY_SPAN = 1.2
"""Synthetic distances are drawn up to this many times what the strongest acceleration
would leave the car needing to stop (:func:`~explaindrive.env.actions.stopping_needs`)."""
SPEED_SHIFT_MPS = 2
"""Synthetic speeds move by up to this many whole m/s."""
_DISTANCES = (S.D_LEAD, S.D_TL, S.D_CROSS)


def boundary_observations(
    obs: NDArray[np.floating], rng: np.random.Generator
) -> NDArray[np.float32]:
    """One synthetic observation per row of ``obs`` (shape ``(B, 8)``), as described in
    the module docstring."""
    x = np.array(obs, dtype=np.float64).reshape(-1, S.STATE_DIM)
    n = len(x)
    shift = rng.integers(-SPEED_SHIFT_MPS, SPEED_SHIFT_MPS + 1, size=n)
    v = np.clip(x[:, S.V_EGO] + shift, 0.0, S.MAX_SPEED_MPS)
    x[:, S.DV] += np.where(x[:, S.D_LEAD] < S.SENSOR_RANGE_M, v - x[:, S.V_EGO], 0.0)
    x[:, S.V_EGO] = v

    target = rng.uniform(0.0, BOUNDARY_SPAN, size=n) * (
        stopping_needs(v + max(SPEED_CHANGES_MPS)) + 1.0
    )
    dist = x[:, _DISTANCES]
    in_range = dist < S.SENSOR_RANGE_M
    nearest = np.where(in_range, dist, np.inf).min(axis=1)
    seen = np.isfinite(nearest)
    factor = np.where(seen, target / np.maximum(nearest, 1e-3), 1.0)
    scaled = np.minimum(dist * factor[:, None], S.SENSOR_RANGE_M - 1.0)
    x[:, _DISTANCES] = np.where(in_range, scaled, dist)

    red = ~seen & (rng.random(n) < 0.5)
    x[red, S.D_TL] = x[red, S.D_LEAD] = target[red]
    x[red, S.TLS] = float(S.LightState.RED)
    x[red, S.DV] = v[red]
    return np.clip(x, S.STATE_LOW, S.STATE_HIGH).astype(np.float32)


def boundary_batch(
    obs: NDArray[np.floating],
    rng: np.random.Generator,
    dilemma_braking: bool,
    noise_max: tuple[float, float] = (0.0, 0.0),
    noisy_share: float = 0.0,
    *,
    speed_limiter: bool = False,
) -> tuple[NDArray[np.float32], NDArray[np.bool_]]:
    """Synthetic observations for a minibatch and their learning masks; with ``noise_max``
    and ``noisy_share`` set, the observations as seen through noise (the module docstring).
    Without noise nothing more is drawn from ``rng``. ``speed_limiter``: the masks judge
    each action through the speed limiter."""
    synthetic = boundary_observations(obs, rng)
    mask = training_mask(synthetic, dilemma_braking, speed_limiter)
    if noisy_share > 0.0 and noise_max != (0.0, 0.0):
        u = rng.uniform(size=(len(synthetic), 3))
        noisy = u[:, 2] < noisy_share
        sd_m = np.where(noisy, u[:, 0] * noise_max[0], 0.0)
        sd_mps = np.where(noisy, u[:, 1] * noise_max[1], 0.0)
        synthetic = noisy_rows(synthetic, sd_m, sd_mps, rng)
    return synthetic, mask
