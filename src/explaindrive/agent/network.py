"""The dueling Q-network; it normalises raw observations itself."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import torch
from torch import Tensor, nn

from explaindrive.agent.targets import dueling_aggregate
from explaindrive.env.actions import N_ACTIONS
from explaindrive.env.state import STATE_DIM, STATE_SCALE


class DuelingQNetwork(nn.Module):
    """MLP trunk, then a value head and an advantage head combined by
    :func:`~explaindrive.agent.targets.dueling_aggregate`.

    The input is the raw observation of :mod:`explaindrive.env.state`; the first thing the
    forward pass does is divide by :data:`~explaindrive.env.state.STATE_SCALE` (the same
    scaling as :func:`explaindrive.env.state.normalize`), so a saved network is used on raw
    observations and the scaling cannot be forgotten.
    """

    inv_scale: Tensor

    def __init__(
        self,
        hidden_sizes: Sequence[int] = (128, 128),
        state_dim: int = STATE_DIM,
        n_actions: int = N_ACTIONS,
    ) -> None:
        super().__init__()
        if state_dim != STATE_DIM:
            raise ValueError(f"state_dim must be {STATE_DIM} (the scaling is per component)")
        if not hidden_sizes or any(int(h) <= 0 for h in hidden_sizes):
            raise ValueError(f"hidden_sizes must be positive ints, got {list(hidden_sizes)}")
        self.hidden_sizes = tuple(int(h) for h in hidden_sizes)
        self.state_dim = state_dim
        self.n_actions = n_actions
        self.register_buffer("inv_scale", torch.from_numpy(1.0 / STATE_SCALE.astype(np.float32)))
        layers: list[nn.Module] = []
        width = state_dim
        for h in self.hidden_sizes:
            layers += [nn.Linear(width, h), nn.ReLU()]
            width = h
        self.trunk = nn.Sequential(*layers)
        self.value = nn.Linear(width, 1)
        self.advantage = nn.Linear(width, n_actions)

    def forward(self, obs: Tensor) -> Tensor:
        """Q-values ``(B, n_actions)`` of raw observations ``(B, state_dim)``."""
        features = self.trunk(obs * self.inv_scale)
        return dueling_aggregate(self.value(features), self.advantage(features))

    @torch.no_grad()
    def greedy(self, obs: np.ndarray) -> np.ndarray:
        """Greedy actions of a batch (or one) raw observation(s), as int64."""
        x = torch.as_tensor(np.asarray(obs, dtype=np.float32))
        single = x.dim() == 1
        q = self(x.unsqueeze(0) if single else x)
        actions = q.argmax(dim=-1).numpy()
        return actions[0] if single else actions
