"""A tiny stand-in for the SUMO env with the same spaces and reset/step contract.

Toy longitudinal dynamics on a straight road with a constant speed limit; the reward
depends on the command active in the step, like the real env (fast / comfort / stop).
"""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from explaindrive.commands import Command
from explaindrive.env.actions import N_ACTIONS, speed_change
from explaindrive.env.safety import runtime_mask
from explaindrive.env.state import SENSOR_RANGE_M, STATE_DIM, STATE_HIGH, STATE_LOW

V_LIM_MPS = 10.0


class FakeDriveEnv(gym.Env[np.ndarray, int]):
    """Fixed-length episodes (``max_steps``) unless ``route_m`` ends them earlier."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": []}

    def __init__(
        self,
        max_steps: int = 20,
        route_m: float | None = None,
        step_delay_s: float = 0.0,
        fail_seeds: tuple[int, ...] = (),
    ):
        self.observation_space = gym.spaces.Box(STATE_LOW, STATE_HIGH, (STATE_DIM,), np.float32)
        self.action_space = gym.spaces.Discrete(N_ACTIONS)
        self.max_steps = max_steps
        self.route_m = route_m
        self.step_delay_s = step_delay_s
        self.fail_seeds = fail_seeds
        self.command = Command.FAST
        self.schedule: list[tuple[float, Command]] = []
        self.v = self.x = 0.0
        self.t = 0

    def set_command(self, command: str | int | Command) -> None:
        self.command = Command.parse(command)

    def _obs(self) -> np.ndarray:
        return np.array(
            [self.command, self.v, V_LIM_MPS, SENSOR_RANGE_M, 0.0, SENSOR_RANGE_M, 0.0,
             SENSOR_RANGE_M],
            dtype=np.float32,
        )  # fmt: skip

    def _true_obs(self) -> np.ndarray:
        """The true state (what ``info["action_mask"]`` is computed on, as in the real env)."""
        return self._obs()

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        if seed in self.fail_seeds:
            raise RuntimeError(f"the ego could not enter (seed {seed})")
        super().reset(seed=seed)
        options = options or {}
        self.command = Command.parse(options.get("command", "fast"))
        self.schedule = [
            (float(t), Command.parse(c)) for t, c in options.get("command_schedule", [])
        ]
        self.v = float(self.np_random.integers(0, 3))
        self.x = 0.0
        self.t = 0
        return self._obs(), {
            "command": self.command.label, "action_mask": runtime_mask(self._true_obs())
        }  # fmt: skip

    def step(self, action: int):
        if self.step_delay_s:
            import time

            time.sleep(self.step_delay_s)
        change = speed_change(int(action))
        cmd = self.command
        self.v = float(np.clip(self.v + change, 0.0, 20.0))
        self.x += self.v
        self.t += 1
        if cmd is Command.STOP:
            reward = 2.0 if self.v == 0 else (-50.0 if change >= 0 else 0.0)
        else:
            gain = 3.0 if cmd is Command.FAST else 1.5
            reward = -10.0 if self.v > V_LIM_MPS else gain * self.v / V_LIM_MPS
        while self.schedule and self.schedule[0][0] <= self.t:
            self.command = self.schedule.pop(0)[1]
        terminated = self.route_m is not None and self.x >= self.route_m
        truncated = not terminated and self.t >= self.max_steps
        info = {
            "command": cmd.label, "speed_mps": self.v, "distance_m": self.x,
            "time_s": float(self.t), "collision": False, "red_light_run": False,
            "ped_violation": False, "speeding": self.v > V_LIM_MPS, "reward_terms": {},
            "action_mask": runtime_mask(self._true_obs()),
        }  # fmt: skip
        return self._obs(), reward, terminated, truncated, info
