"""The dueling Q-network; it normalises raw observations itself."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import torch
from torch import Tensor, nn

from explaindrive.agent.targets import dueling_aggregate
from explaindrive.env import state as S
from explaindrive.env.actions import N_ACTIONS
from explaindrive.env.state import STATE_DIM, STATE_SCALE

DISTANCES = (S.D_LEAD, S.D_TL, S.D_CROSS)
"""The components the near-range features read: the gaps to the leader, the light and the
crossing."""


class DuelingQNetwork(nn.Module):
    """MLP trunk, then a value head and an advantage head combined by
    :func:`~explaindrive.agent.targets.dueling_aggregate`.

    The input is the raw observation of :mod:`explaindrive.env.state`; the first thing the
    forward pass does is divide by :data:`~explaindrive.env.state.STATE_SCALE` (the same
    scaling as :func:`explaindrive.env.state.normalize`), so a saved network is used on raw
    observations and the scaling cannot be forgotten.

    With ``near_range_m`` set, the scaled observation is followed by one near-range feature
    per distance (:data:`DISTANCES`), exp(-d / near_range_m): scaled by the sensor range, a
    metre near a stop line moves the input by 0.005, which a ReLU network resolves poorly;
    the feature moves by about ``1 / near_range_m`` per metre there and fades to 0 far away.
    """

    inv_scale: Tensor

    def __init__(
        self,
        hidden_sizes: Sequence[int] = (128, 128),
        state_dim: int = STATE_DIM,
        n_actions: int = N_ACTIONS,
        near_range_m: float | None = None,
    ) -> None:
        super().__init__()
        if state_dim != STATE_DIM:
            raise ValueError(f"state_dim must be {STATE_DIM} (the scaling is per component)")
        if not hidden_sizes or any(int(h) <= 0 for h in hidden_sizes):
            raise ValueError(f"hidden_sizes must be positive ints, got {list(hidden_sizes)}")
        if near_range_m is not None and not near_range_m > 0.0:
            raise ValueError(f"near_range_m must be positive, got {near_range_m}")
        self.hidden_sizes = tuple(int(h) for h in hidden_sizes)
        self.near_range_m = None if near_range_m is None else float(near_range_m)
        self.state_dim = state_dim
        self.n_actions = n_actions
        self.register_buffer("inv_scale", torch.from_numpy(1.0 / STATE_SCALE.astype(np.float32)))
        layers: list[nn.Module] = []
        width = state_dim + (0 if near_range_m is None else len(DISTANCES))
        for h in self.hidden_sizes:
            layers += [nn.Linear(width, h), nn.ReLU()]
            width = h
        self.trunk = nn.Sequential(*layers)
        self.value = nn.Linear(width, 1)
        self.advantage = nn.Linear(width, n_actions)

    def forward(self, obs: Tensor) -> Tensor:
        """Q-values ``(B, n_actions)`` of raw observations ``(B, state_dim)``."""
        x = obs * self.inv_scale
        if self.near_range_m is not None:
            near = torch.exp(obs[..., list(DISTANCES)] * (-1.0 / self.near_range_m))
            x = torch.cat((x, near), dim=-1)
        features = self.trunk(x)
        return dueling_aggregate(self.value(features), self.advantage(features))

    @torch.no_grad()
    def greedy(self, obs: np.ndarray) -> np.ndarray:
        """Greedy actions of a batch (or one) raw observation(s), as int64."""
        x = torch.as_tensor(np.asarray(obs, dtype=np.float32))
        single = x.dim() == 1
        q = self(x.unsqueeze(0) if single else x)
        actions = q.argmax(dim=-1).numpy()
        return actions[0] if single else actions
