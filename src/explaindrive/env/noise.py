"""Sensor noise on the observation: what the driver sees is not the true state.

Gaussian noise with standard deviation ``sd_m`` on the three distances (leader gap, next
light, next busy crossing) and ``sd_mps`` on the two measured speeds (the ego's speed and
the closing speed to the leader). The command, the posted limit and the light's colour are
exact (the limit comes from the map, the colour is unambiguous). A distance at sensor range
means "nothing detected" and stays so; noisy values are clipped to the state's bounds. The
environment judges violations and computes rewards on the true state.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated

from pydantic import AfterValidator

from explaindrive.config import FROM_LIST

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

# numpy and the state module load when noise is applied, not with the configs that only
# check a noise field (``ride --help`` reads RideConfig)
MAX_NOISE_SD_M = 20.0  # [m] largest accepted standard deviation on distances
MAX_NOISE_SD_MPS = 5.0  # [m/s] largest accepted standard deviation on speeds


@dataclass(frozen=True, slots=True)
class ObservationNoise:
    """Standard deviations of the noise on distances [m] and speeds [m/s]."""

    sd_m: float = 0.0
    sd_mps: float = 0.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.sd_m <= MAX_NOISE_SD_M:
            raise ValueError(f"distance noise must be in [0, {MAX_NOISE_SD_M}] m, got {self.sd_m}")
        if not 0.0 <= self.sd_mps <= MAX_NOISE_SD_MPS:
            raise ValueError(
                f"speed noise must be in [0, {MAX_NOISE_SD_MPS}] m/s, got {self.sd_mps}"
            )

    @property
    def active(self) -> bool:
        """Whether any noise is added."""
        return self.sd_m > 0.0 or self.sd_mps > 0.0

    def apply(self, obs: NDArray[np.float32], rng: np.random.Generator) -> NDArray[np.float32]:
        """A noisy copy of a raw observation (``obs`` is left as it is)."""
        import numpy as np

        if not self.active:
            return obs.astype(np.float32, copy=True)
        row = obs.reshape(1, -1)
        return noisy_rows(row, np.array([self.sd_m]), np.array([self.sd_mps]), rng)[0]


def noisy_rows(
    obs: NDArray[np.floating],
    sd_m: NDArray[np.floating],
    sd_mps: NDArray[np.floating],
    rng: np.random.Generator,
) -> NDArray[np.float32]:
    """Noisy copies of raw observations of shape ``(B, 8)``, row ``i`` with standard
    deviations ``sd_m[i]`` and ``sd_mps[i]``, by the rule of the module docstring. Draws five
    standard normals per row, whatever its deviations (one row draws what
    :meth:`ObservationNoise.apply` does)."""
    import numpy as np

    from explaindrive.env import state as S

    out = np.array(obs, dtype=np.float32).reshape(-1, S.STATE_DIM)
    draws = rng.standard_normal((len(out), 5))
    sd_m, sd_mps = np.asarray(sd_m), np.asarray(sd_mps)
    for k, i in enumerate((S.D_LEAD, S.D_TL, S.D_CROSS)):
        detected = out[:, i] < S.SENSOR_RANGE_M
        out[:, i] = np.where(detected, out[:, i] + sd_m * draws[:, k], out[:, i])
    leader = out[:, S.D_LEAD] < S.SENSOR_RANGE_M  # the noisy gap decides, as for one row
    out[:, S.V_EGO] = out[:, S.V_EGO] + sd_mps * draws[:, 3]
    out[:, S.DV] = np.where(leader, out[:, S.DV] + sd_mps * draws[:, 4], out[:, S.DV])
    return np.clip(out, S.STATE_LOW, S.STATE_HIGH).astype(np.float32)


def parse_noise(text: str) -> ObservationNoise:
    """``"SD_M,SD_MPS"`` (e.g. ``"2,0.6"``) as an :class:`ObservationNoise`.

    Raises:
        ValueError: naming the expected form or the range.
    """
    parts = text.split(",")
    try:
        sd_m, sd_mps = (float(p) for p in parts)
    except ValueError:
        raise ValueError(
            f"observation noise must look like SD_M,SD_MPS (e.g. 2,0.6), got {text!r}"
        ) from None
    return ObservationNoise(sd_m, sd_mps)


def _check_sd(value: tuple[float, float]) -> tuple[float, float]:
    ObservationNoise(*value)  # raises ValueError naming the range
    return value


NoiseSD = Annotated[tuple[float, float], FROM_LIST, AfterValidator(_check_sd)]
"""A config field holding ``(sd_m, sd_mps)``, checked against the accepted ranges."""
