"""Helpers shared by the test packages (fixtures stay in the ``conftest.py`` files)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import torch

from explaindrive.agent.checkpoint import save_policy
from explaindrive.agent.network import DuelingQNetwork


def constant_policy(path: Path, action: int, card: dict[str, Any]) -> Path:
    """A policy file whose network ignores its input: the greedy action is always ``action``
    (an action index); ``card`` is written next to it. Returns the ``.pt`` path."""
    net = DuelingQNetwork((4,))
    with torch.no_grad():
        for p in net.parameters():
            p.zero_()
        net.advantage.bias[action] = 1.0
    policy_path, _ = save_policy(path, net, card)
    return policy_path
