"""Typed, validated training configuration and its two presets.

One frozen dataclass, :class:`TrainConfig`, holds every knob of the D3QN agent and of its
training loop. It is built from a preset (``paper`` or ``safe``), then optionally from a
YAML/JSON file and from ``key=value`` overrides; unknown keys and ill-typed values are
rejected with a message naming the key. The resolved config is saved as JSON next to
every checkpoint and inside every policy card.
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import types
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from explaindrive.commands import Command
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS, validate_traffic_level

_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")

TRAIN_MODES: tuple[str, ...] = (Command.FAST.label, Command.COMFORT.label)
LOSSES: tuple[str, ...] = ("mse", "huber")
SEED_POOL_BASE = 100_000  # training seeds from a pool start here, clear of evaluation seeds


class ConfigError(ValueError):
    """A configuration value, key or file is invalid."""


@dataclass(frozen=True)
class TrainConfig:
    """Everything that defines one training run of a D3QN driving agent.

    Step counts (``*_steps``, ``learning_starts``, ``train_frequency``) are counted in
    environment transitions summed over all parallel environments.
    """

    mode: str = "fast"
    """Primary command the agent is trained for: ``fast`` or ``comfort`` (both learn stop)."""
    episodes: int = 11_000
    """Number of training episodes (the paper: 11,000)."""
    num_envs: int | None = None
    """Parallel SUMO processes; ``None`` means ``os.cpu_count()``."""
    seed: int = 0
    """Base seed of the run: episode seeds, exploration and network initialisation."""

    hidden_sizes: tuple[int, ...] = (128, 128)
    """Widths of the shared fully connected layers (the paper: two of 128)."""
    lr: float = 1e-3
    """Adam learning rate (the paper: 1e-3)."""
    lr_final: float | None = None
    """If set, the learning rate decays linearly to this value over ``lr_decay_steps``."""
    lr_decay_steps: int = 1_000_000
    """Transitions over which the learning rate decays to ``lr_final``."""
    loss: str = "mse"
    """TD loss: ``mse`` (the paper) or ``huber``."""
    huber_delta: float = 1.0
    """Threshold of the Huber loss (only with ``loss="huber"``)."""
    grad_clip_norm: float | None = None
    """Max global gradient norm; ``None`` disables clipping."""
    buffer_size: int = 5_000_000
    """Replay capacity in transitions (the paper: 5M)."""
    batch_size: int = 64
    """Minibatch size (the paper: 64)."""
    gamma: float = 0.99
    """Discount factor (the paper: 0.99)."""
    learning_starts: int = 5_000
    """Transitions collected before the first gradient update."""
    train_frequency: int = 1
    """Transitions per gradient update (1: one update per transition)."""
    target_update_interval: int = 1_000
    """Gradient updates between target-network updates."""
    tau: float = 1.0
    """Target update coefficient: 1.0 copies (hard update), < 1 is Polyak averaging."""
    eps_start: float = 1.0
    """Initial epsilon of the epsilon-greedy exploration."""
    eps_end: float = 0.05
    """Final epsilon."""
    eps_decay_steps: int = 1_000_000
    """Transitions over which epsilon decays linearly from ``eps_start`` to ``eps_end``."""
    eps_final: float | None = None
    """If set, epsilon drops from ``eps_end`` to this value after ``eps_final_after``."""
    eps_final_after: int = 0
    """Transitions after which epsilon is ``eps_final``."""
    n_step: int = 1
    """Steps summed in each bootstrapped return (1: the paper's one-step target)."""

    traffic_levels: tuple[float, ...] = TRAFFIC_LEVELS
    """Traffic levels sampled uniformly per episode (1.0 = 900 veh/h on the main road)."""
    stop_gap_s: tuple[float, float] = (15.0, 60.0)
    """Range [s] of the random time before each injected stop command (even episodes)."""
    stop_duration_s: tuple[float, float] = (5.0, 15.0)
    """Range [s] of the random duration of each injected stop command."""
    schedule_horizon_s: float = 900.0
    """Stop commands are scheduled up to this simulated time [s]."""
    seed_pool: int | None = None
    """If set, episode seeds are drawn from this many values (``SEED_POOL_BASE`` onwards), so
    the env's cached warm-up states are reused; ``None`` gives every episode a fresh seed."""
    rollout_steps: int = 16
    """Env steps each worker plays per round; the workers get new weights every round."""
    max_episode_steps: int | None = None
    """Env step limit per episode; ``None`` keeps the env's default."""
    safe_learning: bool = False
    """Learn the shield's rule into the network (``docs/agent.md``): act through the safety
    mask (:func:`~explaindrive.agent.shield.training_mask`), store it with each transition,
    take the double-DQN argmax over safe actions only and push the Q-values of unsafe
    actions down to ``unsafe_q``. The mask is never an input of the network."""
    unsafe_q: float = -100.0
    """Value the Q-values of unsafe actions are pushed down to (``safe_learning``)."""
    unsafe_loss_weight: float = 1.0
    """Weight of that loss next to the TD loss."""
    shielded_fraction: float = 1.0
    """Share of the episodes (the first ones) that act through the safety mask; the rest act
    on the bare network's choice, still learning from the masks (``safe_learning``)."""
    stop_when_safe: int | None = None
    """End training once this many consecutive finished episodes had no greedy action the
    shield would override and no violation; ``None`` trains all ``episodes``."""

    checkpoint_every_episodes: int = 100
    """Completed episodes between checkpoints (one is also written at the end)."""
    save_replay: bool = True
    """Checkpoint the replay buffer too, so that ``--resume`` loses only recent transitions."""
    log_every_updates: int = 250
    """Gradient updates between TensorBoard loss scalars."""
    torch_threads: int = 1
    """Threads of the learner process (the env processes use one each)."""
    moving_average_window: int = 50
    """Window of the moving average in the training-curve figure (the paper: 50)."""

    def __post_init__(self) -> None:
        _check_types(self)
        problems = list(_problems(self))
        if problems:
            raise ConfigError("invalid training config: " + "; ".join(problems))

    @property
    def envs(self) -> int:
        """Resolved number of parallel environments."""
        return self.num_envs if self.num_envs is not None else max(1, os.cpu_count() or 1)

    @property
    def command(self) -> Command:
        """The primary command as a :class:`~explaindrive.commands.Command`."""
        return Command.parse(self.mode)

    def replace(self, **changes: Any) -> TrainConfig:
        """A copy with some fields changed (validated like :meth:`from_dict`)."""
        return TrainConfig.from_dict({**self.to_dict(), **changes})

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (tuples become lists)."""
        data = dataclasses.asdict(self)
        return {k: list(v) if isinstance(v, tuple) else v for k, v in data.items()}

    def to_json(self) -> str:
        """The config as indented JSON."""
        return json.dumps(self.to_dict(), indent=2, sort_keys=True)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> TrainConfig:
        """Build a config from a mapping, rejecting unknown keys and coercing lists.

        Raises:
            ConfigError: on an unknown key or an invalid value.
        """
        if not isinstance(data, Mapping):
            raise ConfigError(f"a training config must be a mapping, got {type(data).__name__}")
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise ConfigError(
                f"unknown config key(s): {', '.join(unknown)}; "
                f"known keys: {', '.join(sorted(names))}"
            )
        hints = typing.get_type_hints(cls)
        values = {k: _coerce(k, v, hints[k]) for k, v in data.items()}
        return cls(**values)


def _problems(c: TrainConfig) -> typing.Iterator[str]:
    if c.mode not in TRAIN_MODES:
        yield (
            f"mode must be one of {', '.join(TRAIN_MODES)}, got {c.mode!r} "
            "(stop is not a training mode: both agents learn it)"
        )
    if c.loss not in LOSSES:
        yield f"loss must be one of {', '.join(LOSSES)}, got {c.loss!r}"
    positive = (
        "episodes", "lr_decay_steps", "buffer_size", "batch_size", "train_frequency",
        "target_update_interval", "eps_decay_steps", "checkpoint_every_episodes",
        "log_every_updates", "torch_threads", "moving_average_window", "n_step", "rollout_steps",
    )  # fmt: skip
    for name in positive:
        if getattr(c, name) <= 0:
            yield f"{name} must be > 0, got {getattr(c, name)}"
    for name in ("num_envs", "max_episode_steps", "seed_pool", "stop_when_safe"):
        value = getattr(c, name)
        if value is not None and value <= 0:
            yield f"{name} must be > 0 or null, got {value}"
    if not c.hidden_sizes or any(h <= 0 for h in c.hidden_sizes):
        yield f"hidden_sizes must be a non-empty list of positive ints, got {c.hidden_sizes}"
    for name in ("lr", "huber_delta", "schedule_horizon_s"):
        if getattr(c, name) <= 0:
            yield f"{name} must be > 0, got {getattr(c, name)}"
    for name in ("lr_final", "grad_clip_norm"):
        value = getattr(c, name)
        if value is not None and value <= 0:
            yield f"{name} must be > 0 or null, got {value}"
    if not 0.0 <= c.gamma < 1.0:
        yield f"gamma must be in [0, 1), got {c.gamma}"
    if not 0.0 < c.tau <= 1.0:
        yield f"tau must be in (0, 1], got {c.tau}"
    for name in ("eps_start", "eps_end", "eps_final", "shielded_fraction"):
        value = getattr(c, name)
        if value is not None and not 0.0 <= value <= 1.0:
            yield f"{name} must be in [0, 1], got {value}"
    if c.eps_final_after < 0:
        yield f"eps_final_after must be >= 0, got {c.eps_final_after}"
    if c.unsafe_loss_weight < 0:
        yield f"unsafe_loss_weight must be >= 0, got {c.unsafe_loss_weight}"
    if c.learning_starts < 0:
        yield f"learning_starts must be >= 0, got {c.learning_starts}"
    if c.batch_size > c.buffer_size:
        yield f"batch_size ({c.batch_size}) exceeds buffer_size ({c.buffer_size})"
    if not c.traffic_levels:
        yield "traffic_levels must be a non-empty list"
    for level in c.traffic_levels:
        try:
            validate_traffic_level(level)
        except ValueError as exc:
            yield f"traffic_levels: {exc}"
    for name in ("stop_gap_s", "stop_duration_s"):
        lo, hi = getattr(c, name)
        if not 0 < lo <= hi:
            yield f"{name} must be [min, max] with 0 < min <= max, got {[lo, hi]}"


def _check_types(c: TrainConfig) -> None:
    hints = typing.get_type_hints(type(c))
    for f in dataclasses.fields(c):
        _coerce(f.name, getattr(c, f.name), hints[f.name])


def _coerce(name: str, value: Any, hint: Any) -> Any:
    """Check ``value`` against ``hint`` (and turn lists into tuples, ints into floats)."""
    origin = typing.get_origin(hint)
    args = typing.get_args(hint)
    if origin in (types.UnionType, typing.Union):
        if value is None and type(None) in args:
            return None
        inner = [a for a in args if a is not type(None)]
        return _coerce(name, value, inner[0])
    if origin is tuple:
        if not isinstance(value, list | tuple):
            raise ConfigError(f"config key {name!r} must be a list, got {value!r}")
        if len(args) == 2 and args[1] is Ellipsis:
            items = [_coerce(name, v, args[0]) for v in value]
        else:
            if len(value) != len(args):
                raise ConfigError(f"config key {name!r} must have {len(args)} items, got {value!r}")
            items = [_coerce(name, v, a) for v, a in zip(value, args, strict=True)]
        return tuple(items)
    if hint is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"config key {name!r} must be true/false, got {value!r}")
        return value
    if hint is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"config key {name!r} must be an integer, got {value!r}")
        return value
    if hint is float:
        if isinstance(value, str) and _NUMBER.fullmatch(value.strip()):
            value = float(value)  # YAML 1.1 reads "1e-3" (no dot) as a string
        if isinstance(value, bool) or not isinstance(value, int | float) or value != value:
            raise ConfigError(f"config key {name!r} must be a number, got {value!r}")
        return float(value)
    if hint is str:
        if not isinstance(value, str):
            raise ConfigError(f"config key {name!r} must be a string, got {value!r}")
        return value
    return value


PAPER = TrainConfig()
"""The paper's values: 2x128, Adam 1e-3, MSE, 5M replay, batch 64, gamma 0.99, 11,000 episodes."""

SAFE = TrainConfig(
    episodes=1600,
    lr=1e-3,
    lr_final=1e-4,
    lr_decay_steps=400_000,
    loss="huber",
    grad_clip_norm=10.0,
    buffer_size=1_000_000,
    batch_size=128,
    learning_starts=2_000,
    train_frequency=2,
    target_update_interval=1,
    tau=0.005,
    eps_start=1.0,
    eps_end=0.05,
    eps_decay_steps=110_000,
    eps_final=0.01,
    eps_final_after=220_000,
    n_step=3,
    safe_learning=True,
    shielded_fraction=0.85,
    stop_when_safe=200,
    checkpoint_every_episodes=25,
    seed_pool=250,
)
"""The shipped settings: the paper's network, rewards and command schedule, tuned for wall
time on 2 CPU cores (lr decay, one update per two transitions, Polyak-averaged target, Huber
loss with gradient clipping, 3-step returns) and safe learning: the shield's rule is taught
to the network, which acts through it for the first 85 % of the episodes and on its own
after that; training ends early once 200 episodes in a row needed no override."""

PRESETS: dict[str, TrainConfig] = {"paper": PAPER, "safe": SAFE}


def preset(name: str) -> TrainConfig:
    """The named preset.

    Raises:
        ConfigError: if ``name`` is not a preset.
    """
    try:
        return PRESETS[name]
    except KeyError:
        raise ConfigError(
            f"unknown preset {name!r}; expected one of: {', '.join(PRESETS)}"
        ) from None


def load_config_file(path: str | Path) -> dict[str, Any]:
    """Read a YAML or JSON mapping of config overrides.

    Raises:
        ConfigError: if the file is missing, unparsable or not a mapping.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"cannot read config file {path}: {exc}") from exc
    try:
        data = json.loads(text) if path.suffix == ".json" else yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise ConfigError(f"cannot parse config file {path}: {exc}") from exc
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"config file {path} must hold a mapping, got {type(data).__name__}")
    return data


def parse_override(item: str) -> tuple[str, Any]:
    """Parse one ``key=value`` override; the value is read as YAML (``1e-4``, ``[64, 64]``).

    Raises:
        ConfigError: if ``item`` has no ``=``.
    """
    key, sep, raw = item.partition("=")
    if not sep or not key.strip():
        raise ConfigError(f"override {item!r} must look like key=value")
    try:
        value = yaml.safe_load(raw)
    except yaml.YAMLError as exc:
        raise ConfigError(f"cannot parse the value of override {item!r}: {exc}") from exc
    return key.strip(), value


def build_config(
    preset_name: str = "safe",
    config_file: str | Path | None = None,
    overrides: Mapping[str, Any] | None = None,
) -> TrainConfig:
    """Preset, then file, then explicit overrides (later wins).

    Raises:
        ConfigError: on an unknown preset, key or an invalid value.
    """
    data = preset(preset_name).to_dict()
    if config_file is not None:
        data.update(load_config_file(config_file))
    data.update(overrides or {})
    return TrainConfig.from_dict(data)
