"""Helpers shared by the test packages (fixtures stay in the ``conftest.py`` files)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType
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


SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"


def load_script(name: str) -> ModuleType:
    """The module of ``scripts/<name>.py`` (the scripts are not a package)."""
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # a dataclass of the script looks its module up there
    spec.loader.exec_module(module)
    return module
