"""The merged driving controller: routes each passenger command to a trained policy.

fast -> the fast agent; comfort -> the comfort agent; stop -> whichever of the two was
active, fed ``cmd = 2`` (both agents are trained to obey stop). The shipped policies live
in the package at ``explaindrive/agent/policies/{fast,comfort}.pt``, each with a JSON card.
"""

from __future__ import annotations

import importlib.resources
import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import torch

from explaindrive.agent.checkpoint import CheckpointError, load_policy, policy_file
from explaindrive.agent.estimator import SpeedEstimator, commanded_change
from explaindrive.agent.network import DuelingQNetwork
from explaindrive.agent.shield import shield
from explaindrive.commands import Command
from explaindrive.env.lights import DEFAULT_YELLOW_LEADER
from explaindrive.env.metrics import stop_latency_bound
from explaindrive.env.state import CMD, STATE_DIM, V_EGO, V_LIM

log = logging.getLogger(__name__)

SHIPPED_POLICIES: tuple[str, ...] = (Command.FAST.label, Command.COMFORT.label)


def shipped_policy_path(name: str) -> Path:
    """Path of a shipped policy file (``fast`` or ``comfort``).

    Raises:
        ValueError: if ``name`` is not a shipped policy.
    """
    if name not in SHIPPED_POLICIES:
        raise ValueError(f"no shipped policy {name!r}; expected one of {SHIPPED_POLICIES}")
    root = importlib.resources.files("explaindrive.agent") / "policies" / f"{name}.pt"
    return Path(str(root))


def shipped_training_log(name: str) -> Path:
    """Per-episode training log (``episodes.csv``) of a shipped policy."""
    return shipped_policy_path(name).with_name(f"{name}_episodes.csv")


@dataclass
class QPolicy:
    """A greedy policy over a trained Q-network; takes raw observations."""

    network: DuelingQNetwork
    card: dict[str, Any]

    @classmethod
    def load(cls, path: str | Path) -> QPolicy:
        """Load ``path`` (``.pt``) and the card next to it (raises ``CheckpointError``)."""
        net, card = load_policy(Path(path))
        return cls(net, card)

    @torch.no_grad()
    def q_values(self, obs: np.ndarray) -> np.ndarray:
        """Q-values of one raw observation, shape ``(n_actions,)``."""
        x = torch.as_tensor(np.asarray(obs, dtype=np.float32)).reshape(1, STATE_DIM)
        return self.network(x)[0].numpy()

    def act(self, obs: np.ndarray) -> int:
        """Greedy action of one raw observation."""
        return int(np.argmax(self.q_values(obs)))

    @property
    def speed_estimate(self) -> bool:
        """Whether the network was trained on the controller's speed estimate (its card's
        ``config.speed_estimate``; a card without it: on the speed readings)."""
        return bool(self.card.get("config", {}).get("speed_estimate", False))

    @property
    def yellow_leader(self) -> str:
        """The environment's rule for yellow lights the network was trained with (its card's
        ``config.yellow_leader``; a card without it predates the field: the default)."""
        return str(self.card.get("config", {}).get("yellow_leader", DEFAULT_YELLOW_LEADER))

    @property
    def speed_limiter(self) -> bool:
        """Whether the network was trained with the speed limiter on (its card's
        ``config.speed_limiter``; a card without it predates the limiter: off)."""
        return bool(self.card.get("config", {}).get("speed_limiter", False))


class CommandSource(Protocol):
    """What holds the passenger's command: :class:`~explaindrive.env.urban_drive.UrbanDriveEnv`."""

    @property
    def command(self) -> Command: ...


class MergedController:
    """Switches between the fast and comfort policies at runtime.

    Args:
        fast: the fast-driving policy.
        comfort: the comfort-driving policy.
        command: the initial command (stop starts on the fast agent).
        use_shield: pass the greedy action through the kinematic safety shield
            (:mod:`explaindrive.agent.shield`). Either way ``overrides`` counts the steps
            in which the shield replaced the network's choice (or, without the shield,
            would have), ``steps`` the actions chosen, ``last_override`` tells whether
            the last action was such a step and ``last_network_action`` is what the network
            chose in it.

    Call :meth:`begin` when a ride starts: under a noisy speed sensor the controller then
    estimates its own speed (:class:`~explaindrive.agent.estimator.SpeedEstimator`), and a
    network trained on that estimate (:attr:`QPolicy.speed_estimate`) and its shield read it
    in place of the speed reading; the others read the readings they were trained on.
    """

    def __init__(
        self,
        fast: QPolicy,
        comfort: QPolicy,
        command: Command | str = Command.FAST,
        use_shield: bool = True,
    ):
        self.policies = {Command.FAST: fast, Command.COMFORT: comfort}
        self.active_agent = Command.FAST
        self.command = Command.FAST
        self.use_shield = use_shield
        self.overrides = 0
        self.steps = 0
        self.last_override = False
        self.last_network_action: int | None = None
        self.last_seen: np.ndarray | None = None
        """The observation the active network and its shield read in the last step: the
        speed estimate in place of the reading for a network trained on it."""
        self._stop_steps_left: int | None = None  # under STOP: steps left to a standstill
        self.estimator: SpeedEstimator | None = None
        self._last_change: float | None = None
        self.set_command(command)

    def begin(self, speed_noise_sd_mps: float = 0.0) -> None:
        """A ride starts, at a standstill, with a speed sensor of this noise [m/s]: from now
        on the controller estimates its speed from the readings and its own actions, for the
        networks trained on that estimate."""
        self.estimator = SpeedEstimator(speed_noise_sd_mps)
        self._last_change = None

    @property
    def yellow_leader(self) -> str:
        """The environment's rule for yellow lights both networks were trained with, which
        the controller must drive in: their observations depend on it.

        Raises:
            CheckpointError: if the two networks were trained with different rules.
        """
        rules = {p.yellow_leader for p in self.policies.values()}
        if len(rules) > 1:
            raise CheckpointError(
                "the fast and comfort networks were trained with different yellow-light "
                f"rules ({', '.join(sorted(rules))}); merge networks trained alike"
            )
        return rules.pop()

    @property
    def speed_limiter(self) -> bool:
        """Whether the car drives with the speed limiter: when either network was trained
        with it. The limiter belongs to the car, so both networks and their shields drive
        through it. A network trained without it learned to keep under the posted limit by
        itself, and the limiter only cuts a rise past the limit and slows a car above it
        that keeps its speed: the shipped comfort network drives the validation grids
        through it exactly as without it (docs/agent.md).
        """
        return any(p.speed_limiter for p in self.policies.values())

    @classmethod
    def from_files(
        cls, fast_path: str | Path, comfort_path: str | Path, use_shield: bool = True
    ) -> MergedController:
        """Controller over two policy files."""
        return cls(QPolicy.load(fast_path), QPolicy.load(comfort_path), use_shield=use_shield)

    @classmethod
    def from_package(
        cls,
        use_shield: bool = True,
        fast: str | Path | None = None,
        comfort: str | Path | None = None,
    ) -> MergedController:
        """Controller over the policies shipped with the package, or over ``fast`` /
        ``comfort`` in their place (a policy ``.pt`` file or a training run directory).

        Raises:
            CheckpointError: naming the file, if a policy is missing or corrupt.
        """
        paths = [_policy_path(n, o) for n, o in zip(SHIPPED_POLICIES, (fast, comfort), strict=True)]
        return cls.from_files(paths[0], paths[1], use_shield=use_shield)

    def set_command(self, command: Command | str | int) -> None:
        """Apply a passenger command; stop keeps the current agent."""
        cmd = Command.parse(command)
        if cmd is not Command.STOP:
            self.active_agent = cmd
        if cmd is not Command.STOP:
            self._stop_steps_left = None
        if cmd is not self.command:
            log.debug("command %s -> %s (agent %s)", self.command.label, cmd.label,
                      self.active_agent.label)  # fmt: skip
        self.command = cmd

    def follow(self, env: CommandSource) -> None:
        """Take the passenger's command from ``env``, its one owner, before an action.

        Whoever changes the command (a passenger in a ride or on the page, an evaluation's
        schedule) changes it on the environment (``env.set_command`` or the ``command`` and
        ``command_schedule`` reset options); the controller follows it with this call.
        """
        self.set_command(env.command)

    @property
    def policy(self) -> QPolicy:
        """The policy currently driving."""
        return self.policies[self.active_agent]

    def observation(self, obs: np.ndarray) -> np.ndarray:
        """``obs`` with its ``cmd`` component set to the current command."""
        x = np.array(obs, dtype=np.float32).reshape(STATE_DIM)
        x[CMD] = float(self.command)
        return x

    def act(self, obs: np.ndarray) -> int:
        """Action of the active agent for a raw observation under the current command."""
        x = self.observation(obs)
        speed = float(x[V_EGO])
        if self.estimator is not None:  # tracks the speed whichever network drives
            speed = self.estimator.update(speed, self._last_change)
            if self.policy.speed_estimate:
                x[V_EGO] = speed
        self.last_seen = x
        steps_left = None
        if self.command is Command.STOP:
            if self._stop_steps_left is None:  # the first step under this STOP
                self._stop_steps_left = stop_latency_bound(float(x[V_EGO]))
            steps_left = self._stop_steps_left
            self._stop_steps_left = max(1, self._stop_steps_left - 1)
        q_values = self.policy.q_values(x)
        limiter = self.speed_limiter
        decision = shield(x, q_values, steps_left, limiter)
        self.steps += 1
        self.last_network_action = int(np.argmax(q_values))
        self.last_override = decision.overridden
        self.overrides += int(decision.overridden)
        action = decision.action if self.use_shield else self.last_network_action
        self._last_change = commanded_change(speed, action, float(x[V_LIM]), limiter)
        return action


def _policy_path(name: str, override: str | Path | None) -> Path:
    """``override`` (a training run directory holds its ``policy.pt``), else the shipped
    ``name`` policy.

    Raises:
        CheckpointError: if the shipped policy is not installed.
    """
    if override is not None:
        return policy_file(override)
    path = shipped_policy_path(name)
    if not path.is_file():
        raise CheckpointError(
            f"shipped policy not found: {path}; train one with "
            f"`explaindrive train --mode {name}` and copy its policy.pt/.json there"
        )
    return path
