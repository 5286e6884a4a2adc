"""The paper's 8-dimensional state: the one place that fixes its layout and units.

``s = (cmd, v_ego, v_lim, d_lead, dv, d_tl, tls, d_cross)``

========  =====  ==============  ==========================================================
index     name   unit / range    meaning
========  =====  ==============  ==========================================================
0         cmd    {0, 1, 2}       passenger command: 0 fast, 1 comfort, 2 stop
1         v_ego  m/s, [0, 20]    ego speed
2         v_lim  m/s, [0, 20]    speed limit of the ego's current lane
3         d_lead m, [0, 200]     gap to the leader (real or virtual); 200 = no leader in range
4         dv     m/s, [-20, 20]  ego speed minus leader speed (> 0 when closing); 0 = no leader
5         d_tl   m, [0, 200]     distance to the next traffic light's stop line; 200 = none
6         tls    {0, 1, 2}       its state: 0 green, 1 yellow, 2 red; 0 when there is no light
7         d_cross m, [0, 200]    distance to the next pedestrian crossing with a pedestrian on
                                 or entering it; 200 = no such pedestrian in range
========  =====  ==============  ==========================================================

Distances are measured along the ego's route from its front bumper. Anything
beyond :data:`SENSOR_RANGE_M` is reported as :data:`SENSOR_RANGE_M`.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from numpy.typing import NDArray

SENSOR_RANGE_M = 200.0  # [m] perception range; also the "nothing detected" value
MAX_SPEED_MPS = 20.0  # [m/s] upper bound of v_ego and v_lim in the observation space

STATE_NAMES: tuple[str, ...] = ("cmd", "v_ego", "v_lim", "d_lead", "dv", "d_tl", "tls", "d_cross")
STATE_DIM = len(STATE_NAMES)

CMD, V_EGO, V_LIM, D_LEAD, DV, D_TL, TLS, D_CROSS = range(STATE_DIM)

STATE_LOW = np.array([0.0, 0.0, 0.0, 0.0, -MAX_SPEED_MPS, 0.0, 0.0, 0.0], dtype=np.float32)
STATE_HIGH = np.array(
    [
        2.0,
        MAX_SPEED_MPS,
        MAX_SPEED_MPS,
        SENSOR_RANGE_M,
        MAX_SPEED_MPS,
        SENSOR_RANGE_M,
        2.0,
        SENSOR_RANGE_M,
    ],
    dtype=np.float32,
)
# Scales of the optional normalisation: the largest magnitude of each component, so that
# every normalised component lies in [-1, 1].
STATE_SCALE = np.maximum(np.abs(STATE_LOW), np.abs(STATE_HIGH)).astype(np.float32)


class LightState(IntEnum):
    """Traffic-light colour as encoded in the ``tls`` component."""

    GREEN = 0
    YELLOW = 1
    RED = 2

    @property
    def label(self) -> str:
        """Lower-case colour name (``green``, ``yellow``, ``red``)."""
        return self.name.lower()

    @classmethod
    def from_sumo(cls, char: str) -> LightState:
        """Map one character of a SUMO signal state string to a colour."""
        if char in "rRsu":  # red, red-without-priority, stop-and-go, red-yellow
            return cls.RED
        if char in "yY":
            return cls.YELLOW
        return cls.GREEN  # 'G', 'g', 'o', 'O'


@dataclass(frozen=True, slots=True)
class DrivingState:
    """The 8-dim state as named fields, with physical units."""

    cmd: int
    v_ego: float  # [m/s]
    v_lim: float  # [m/s]
    d_lead: float  # [m]
    dv: float  # [m/s] ego minus leader, > 0 when closing
    d_tl: float  # [m]
    tls: int
    d_cross: float  # [m]

    def to_array(self) -> NDArray[np.float32]:
        """The observation vector in :data:`STATE_NAMES` order."""
        return np.array(
            [
                self.cmd,
                self.v_ego,
                self.v_lim,
                self.d_lead,
                self.dv,
                self.d_tl,
                self.tls,
                self.d_cross,
            ],
            dtype=np.float32,
        )

    @classmethod
    def from_array(cls, obs: NDArray[np.floating]) -> DrivingState:
        """Rebuild the named state from a raw (not normalised) observation vector."""
        if obs.shape != (STATE_DIM,):
            raise ValueError(f"expected a state of shape ({STATE_DIM},), got {obs.shape}")
        return cls(
            cmd=round(float(obs[CMD])),
            v_ego=float(obs[V_EGO]),
            v_lim=float(obs[V_LIM]),
            d_lead=float(obs[D_LEAD]),
            dv=float(obs[DV]),
            d_tl=float(obs[D_TL]),
            tls=round(float(obs[TLS])),
            d_cross=float(obs[D_CROSS]),
        )

    @property
    def has_leader(self) -> bool:
        """Whether a leader (real or virtual) is within sensor range."""
        return self.d_lead < SENSOR_RANGE_M

    @property
    def has_light(self) -> bool:
        """Whether a traffic light is within sensor range."""
        return self.d_tl < SENSOR_RANGE_M

    @property
    def has_pedestrian(self) -> bool:
        """Whether a pedestrian crossing is occupied within sensor range."""
        return self.d_cross < SENSOR_RANGE_M


def normalize(obs: NDArray[np.floating]) -> NDArray[np.float32]:
    """Scale a raw observation (or a batch of them) into [-1, 1] per component."""
    return (np.asarray(obs, dtype=np.float32) / STATE_SCALE).astype(np.float32)


def denormalize(obs: NDArray[np.floating]) -> NDArray[np.float32]:
    """Inverse of :func:`normalize`."""
    return (np.asarray(obs, dtype=np.float32) * STATE_SCALE).astype(np.float32)
