"""Typed, validated training configuration and its two presets.

One frozen model, :class:`TrainConfig`, holds every knob of the D3QN agent and of its
training loop. It is built from a preset (``paper`` or ``safe``), then optionally from a
YAML/JSON file and from ``key=value`` overrides; unknown keys and ill-typed values are
rejected with a message naming the key (:class:`~explaindrive.config.ConfigModel`). The
resolved config is saved as JSON next to every checkpoint and inside every policy card.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any

import yaml
from pydantic import (
    Field,
    NonNegativeFloat,
    NonNegativeInt,
    PositiveFloat,
    PositiveInt,
    field_validator,
    model_validator,
)

from explaindrive import limits
from explaindrive.commands import Command
from explaindrive.config import (
    FROM_LIST,
    ConfigError,
    ConfigModel,
    Seed,
    TrafficLevel,
    one_of,
    read_yaml,
)
from explaindrive.env.curriculum import SCHEDULE_HORIZON_S, STOP_DURATION_S, STOP_GAP_S
from explaindrive.env.curriculum import SEED_POOL_BASE as SEED_POOL_BASE  # re-exported
from explaindrive.env.lights import DEFAULT_YELLOW_LEADER, YELLOW_LEADERS
from explaindrive.env.noise import NoiseSD
from explaindrive.env.reward import REWARD_NAMES, StopWindow
from explaindrive.sim.scenario.choice import ScenarioFields
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS

TRAIN_MODES: tuple[str, ...] = (Command.FAST.label, Command.COMFORT.label)
LOSSES: tuple[str, ...] = ("mse", "huber")

Fraction = Annotated[float, Field(ge=0.0, le=1.0)]  # a probability or a share
Range = Annotated[tuple[float, float], FROM_LIST]  # [min, max], 0 < min <= max


class TrainConfig(ConfigModel, ScenarioFields):
    """Everything that defines one training run of a D3QN driving agent.

    Step counts (``*_steps``, ``learning_starts``, ``train_frequency``) are counted in
    environment transitions summed over all parallel environments.
    """

    config_name = "training config"

    mode: str = "fast"
    """Primary command the agent is trained for: ``fast`` or ``comfort`` (both learn stop)."""
    episodes: Annotated[int, Field(gt=0, le=limits.MAX_EPISODES)] = 11_000
    """Number of training episodes (the paper: 11,000), at most
    :data:`~explaindrive.limits.MAX_EPISODES`."""
    num_envs: Annotated[int, Field(gt=0, le=limits.MAX_WORKERS)] | None = None
    """Parallel SUMO processes (at most :data:`~explaindrive.limits.MAX_WORKERS`); ``None``
    means ``os.cpu_count()``."""
    seed: Seed = 0
    """Base seed of the run: episode seeds, exploration and network initialisation."""

    hidden_sizes: Annotated[tuple[PositiveInt, ...], FROM_LIST, Field(min_length=1)] = (128, 128)
    """Widths of the shared fully connected layers (the paper: two of 128)."""
    near_range_m: PositiveFloat | None = None
    """If set, the network also reads exp(-d / near_range_m) of each of the three distances
    (:class:`~explaindrive.agent.network.DuelingQNetwork`): a fine input near a leader or a
    stop line; ``None``: the 8 scaled components alone (the paper)."""
    lr: PositiveFloat = 1e-3
    """Adam learning rate (the paper: 1e-3)."""
    lr_final: PositiveFloat | None = None
    """If set, the learning rate decays linearly to this value over ``lr_decay_steps``."""
    lr_decay_steps: PositiveInt = 1_000_000
    """Transitions over which the learning rate decays to ``lr_final``."""
    loss: Annotated[str, one_of(LOSSES)] = "mse"
    """TD loss: ``mse`` (the paper) or ``huber``."""
    huber_delta: PositiveFloat = 1.0
    """Threshold of the Huber loss (only with ``loss="huber"``)."""
    grad_clip_norm: PositiveFloat | None = None
    """Max global gradient norm; ``None`` disables clipping."""
    buffer_size: Annotated[int, Field(gt=0, le=limits.MAX_REPLAY)] = 5_000_000
    """Replay capacity in transitions (the paper: 5M), at most
    :data:`~explaindrive.limits.MAX_REPLAY` (about 80 B each, allocated at the start)."""
    batch_size: PositiveInt = 64
    """Minibatch size (the paper: 64)."""
    gamma: float = Field(default=0.99, ge=0.0, lt=1.0)
    """Discount factor (the paper: 0.99)."""
    learning_starts: NonNegativeInt = 5_000
    """Transitions collected before the first gradient update."""
    train_frequency: PositiveInt = 1
    """Transitions per gradient update (1: one update per transition)."""
    target_update_interval: PositiveInt = 1_000
    """Gradient updates between target-network updates."""
    tau: float = Field(default=1.0, gt=0.0, le=1.0)
    """Target update coefficient: 1.0 copies (hard update), < 1 is Polyak averaging."""
    eps_start: Fraction = 1.0
    """Initial epsilon of the epsilon-greedy exploration."""
    eps_end: Fraction = 0.05
    """Final epsilon."""
    eps_decay_steps: PositiveInt = 1_000_000
    """Transitions over which epsilon decays linearly from ``eps_start`` to ``eps_end``."""
    eps_final: Fraction | None = None
    """If set, epsilon drops from ``eps_end`` to this value after ``eps_final_after``."""
    eps_final_after: NonNegativeInt = 0
    """Transitions after which epsilon is ``eps_final``."""
    n_step: PositiveInt = 1
    """Steps summed in each bootstrapped return (1: the paper's one-step target)."""
    n_step_cut: bool = False
    """End each n-step return at the first exploratory action after its first step and
    bootstrap from the state that action was taken in (Watkins's cut of Q(lambda)): the
    returns then carry no exploration but their own first action's. An action is
    exploratory when it is not the network's best one (the best allowed one in shielded
    episodes)."""
    priority_alpha: Fraction = 0.0
    """Prioritised replay (:mod:`explaindrive.agent.prioritized`): transitions are sampled in
    proportion to their priority (absolute TD error) to this power; 0 samples uniformly
    (the paper)."""
    priority_beta: Fraction = 0.4
    """Importance-sampling exponent at the start of prioritised replay, annealed linearly to
    1 over ``priority_beta_steps`` transitions."""
    priority_beta_steps: PositiveInt = 400_000
    """Transitions over which ``priority_beta`` rises to 1."""

    traffic_levels: Annotated[tuple[TrafficLevel, ...], FROM_LIST, Field(min_length=1)] = (
        TRAFFIC_LEVELS
    )
    """Traffic levels sampled uniformly per episode (1.0 = 900 veh/h on the main road)."""
    stop_gap_s: Range = STOP_GAP_S
    """Range [s] of the random time before each injected stop command (even episodes)."""
    stop_duration_s: Range = STOP_DURATION_S
    """Range [s] of the random duration of each injected stop command."""
    schedule_horizon_s: PositiveFloat = SCHEDULE_HORIZON_S
    """Stop commands are scheduled up to this simulated time [s]."""
    seed_pool: PositiveInt | None = None
    """If set, episode seeds are drawn from this many values (``SEED_POOL_BASE`` onwards), so
    the env's cached warm-up states are reused; ``None`` gives every episode a fresh seed."""
    rollout_steps: PositiveInt = 16
    """Env steps each worker plays per round; the workers get new weights every round."""
    max_episode_steps: PositiveInt | None = None
    """Env step limit per episode; ``None`` keeps the env's default."""
    safe_learning: bool = False
    """Learn the shield's rule into the network (``docs/agent.md``): act through the safety
    mask (:func:`~explaindrive.agent.shield.training_mask`), store it with each transition,
    take the double-DQN argmax over safe actions only and push the Q-values of unsafe
    actions down to ``unsafe_q``. The mask is never an input of the network."""
    unsafe_q: float = -100.0
    """Value the Q-values of unsafe actions are pushed down to (``safe_learning``)."""
    unsafe_loss_weight: NonNegativeFloat = 1.0
    """Weight of that loss next to the TD loss."""
    unsafe_margin: PositiveFloat | None = None
    """If set, unsafe actions are pushed to this far below the best safe action of their
    state instead of to ``unsafe_q`` (a large-margin loss; ``safe_learning``)."""
    limit_margin: PositiveFloat | None = None
    """If set (with ``unsafe_margin``), the actions that exceed the posted limit at the speed
    the network sees are pushed this far below the best safe action, and the other unsafe
    actions ``unsafe_margin``; on the synthetic rows too, unless ``boundary_margin`` is
    set."""
    yellow_leader: Annotated[str, one_of(YELLOW_LEADERS)] = DEFAULT_YELLOW_LEADER
    """When the environment makes a yellow light's stop line a virtual leader: ``decided``
    once by whether the car can still stop there, or ``always`` (the paper; see
    :mod:`explaindrive.env.lights`). A network is evaluated with the rule it was trained
    with."""
    reward: Annotated[str, one_of(REWARD_NAMES)] = "paper"
    """The reward recipe (:mod:`explaindrive.env.reward`): ``paper`` (R0/R1/R2) or
    ``passenger`` (the same terms, weighted for a ride a passenger would choose)."""
    stop_window_m: StopWindow | None = None
    """``(min, max)`` metres before the line within which the reward pays standing for a
    light or a pedestrian; ``None``: the recipe's own
    (:attr:`~explaindrive.env.reward.RewardWeights.stop_window_m`)."""
    speed_limiter: bool = False
    """The speed limiter (Intelligent Speed Assistance): a speed rise that would pass the
    posted limit lands on it (:func:`~explaindrive.env.actions.limited_speed`), in the
    environment, the safety masks and the shield. ``passenger`` turns it on; ``paper`` keeps
    the paper's dynamics."""
    obs_noise_max: NoiseSD = (0.0, 0.0)
    """``(sd_m, sd_mps)``: a share ``noisy_share`` of the episodes draws its observation noise
    uniformly between 0 and these (domain randomisation, :mod:`explaindrive.env.noise`);
    the safety masks of learning are computed on the true state."""
    noisy_share: Fraction = 0.5
    """Share of the episodes with observation noise (when ``obs_noise_max`` is not zero)."""
    speed_noisy_share: Fraction | None = None
    """If set, the share of the episodes with noise on the speeds, drawn apart from the
    distances' (which keep ``noisy_share``); ``None``: the speeds are noisy in the episodes
    whose distances are."""
    speed_estimate: bool = False
    """Whether the network sees, in noisy episodes, the controller's estimate of its speed:
    the reading fused with its own speed changes
    (:class:`~explaindrive.agent.estimator.SpeedEstimator`), not the reading. The run-time
    controller then shows it the estimate too."""
    boundary_weight: NonNegativeFloat = 0.0
    """Weight of the unsafe-action loss on one synthetic observation per minibatch row, moved
    near the safety boundary (:mod:`explaindrive.agent.boundary`; ``safe_learning``); 0
    turns it off."""
    boundary_margin: PositiveFloat | None = None
    """How far below the best safe action the unsafe actions of those synthetic rows are
    pushed; ``None`` uses ``unsafe_margin``."""
    boundary_noise: bool = False
    """Whether the network sees those synthetic rows through observation noise drawn as the
    episodes' (``obs_noise_max``, ``noisy_share`` for the speeds too, whatever
    ``speed_noisy_share``), their masks staying those of the noise-free rows: it learns which
    actions may be unsafe for what it sees."""
    dilemma_braking: bool = True
    """Whether the safety mask of learning leaves braking in a yellow light's dilemma zone
    (where even the hardest braking cannot stop before the line) to the rewards; ``False``
    marks it unsafe, as the run-time shield does (``safe_learning``)."""
    shielded_fraction: Fraction = 1.0
    """Share of the episodes (the first ones) that act through the safety mask; the rest act
    on the bare network's choice, still learning from the masks (``safe_learning``)."""
    stop_when_safe: PositiveInt | None = None
    """End training once this many consecutive finished episodes had no greedy action the
    shield would override and no violation; ``None`` trains all ``episodes``."""

    checkpoint_every_episodes: PositiveInt = 100
    """Completed episodes between checkpoints (one is also written at the end)."""
    save_replay: bool = True
    """Checkpoint the replay buffer too, so that ``--resume`` loses only recent transitions."""
    log_every_updates: PositiveInt = 250
    """Gradient updates between TensorBoard loss scalars."""
    torch_threads: PositiveInt = 1
    """Threads of the learner process (the env processes use one each)."""
    moving_average_window: PositiveInt = 50
    """Window of the moving average in the training-curve figure (the paper: 50)."""

    @field_validator("mode")
    @classmethod
    def _training_mode(cls, mode: str) -> str:
        if mode not in TRAIN_MODES:
            raise ValueError(
                f"must be one of {', '.join(TRAIN_MODES)}, got {mode!r} "
                "(stop is not a training mode: both agents learn it)"
            )
        return mode

    @field_validator("stop_gap_s", "stop_duration_s")
    @classmethod
    def _ordered_range(cls, bounds: tuple[float, float]) -> tuple[float, float]:
        lo, hi = bounds
        if not 0 < lo <= hi:
            raise ValueError(f"must be [min, max] with 0 < min <= max, got {[lo, hi]}")
        return bounds

    @model_validator(mode="after")
    def _limit_margin_needs_margins(self) -> TrainConfig:
        if self.limit_margin is not None and self.unsafe_margin is None:
            raise ValueError("limit_margin needs unsafe_margin (pushes relative to the best safe)")
        return self

    @model_validator(mode="after")
    def _boundary_noise_needs_noise(self) -> TrainConfig:
        if self.boundary_noise and (
            self.obs_noise_max == (0.0, 0.0) or self.boundary_weight == 0.0
        ):
            raise ValueError("boundary_noise needs obs_noise_max and boundary_weight")
        return self

    @model_validator(mode="after")
    def _batch_fits_buffer(self) -> TrainConfig:
        if self.batch_size > self.buffer_size:
            raise ValueError(
                f"batch_size ({self.batch_size}) exceeds buffer_size ({self.buffer_size})"
            )
        return self

    @property
    def envs(self) -> int:
        """Resolved number of parallel environments."""
        return self.num_envs if self.num_envs is not None else max(1, os.cpu_count() or 1)

    @property
    def command(self) -> Command:
        """The primary command as a :class:`~explaindrive.commands.Command`."""
        return Command.parse(self.mode)


PAPER = TrainConfig(yellow_leader="always")
"""The paper's values: 2x128, Adam 1e-3, MSE, 5M replay, batch 64, gamma 0.99, 11,000 episodes,
and its virtual leader at every yellow light."""

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

PASSENGER = SAFE.replace(
    episodes=1200,
    reward="passenger",
    yellow_leader="gentle",
    unsafe_margin=30.0,
    boundary_weight=0.25,
    obs_noise_max=(3.0, 0.9),
    stop_when_safe=None,
    scenario="random",
    scenario_paper_share=0.25,
    speed_limiter=True,
)
"""The default: ``safe``'s learning with the ``passenger`` reward recipe, the speed limiter
(:func:`~explaindrive.env.actions.limited_speed`) and the ``gentle``
decision at yellow (:mod:`explaindrive.env.lights`) over 1,200 episodes (the shipped
networks' budget), the unsafe-action loss also on synthetic rows near the safety boundary at
a quarter of its weight (:mod:`explaindrive.agent.boundary`), observation noise up to 3 m /
0.9 m/s drawn in half of the episodes, every episode trained (no early end: a run that is
safe early still has to learn to drive well), on the scenario family: a new scenario every 20
episodes, the paper's road in a quarter of the draws and generated ones in the rest. Its
comfort network has settings of its own (:data:`MODE_SETTINGS`)."""

PRESETS: dict[str, TrainConfig] = {"paper": PAPER, "safe": SAFE, "passenger": PASSENGER}
DEFAULT_PRESET = "passenger"

_PASSENGER_NETWORKS: dict[str, Any] = {
    "n_step_cut": True,
    "speed_noisy_share": 1.0,
    "near_range_m": 15.0,
    "speed_estimate": True,
}

MODE_SETTINGS: dict[str, dict[str, dict[str, Any]]] = {
    "passenger": {
        "fast": {**_PASSENGER_NETWORKS, "unsafe_loss_weight": 4.0},
        "comfort": {**_PASSENGER_NETWORKS, "stop_window_m": (1.0, 4.0)},
    },
}
"""Per preset and mode, the settings a preset's fast or comfort network is trained with
besides the preset's own. ``passenger``'s networks: returns cut at exploration (Watkins),
noise on the speeds in every episode (on the distances in half, as the preset), the
near-range distance features, and the controller's speed estimate in place of the speed
reading; fast weighs the unsafe-action loss four times, and comfort is paid for standing
only within 1-4 m of the line (a metre inside the ride target's 1-5 m)."""


def preset(name: str, mode: str | None = None) -> TrainConfig:
    """The named preset; with ``mode``, for that mode: its :data:`MODE_SETTINGS` applied.

    Raises:
        ConfigError: if ``name`` is not a preset or ``mode`` not a mode.
    """
    try:
        base = PRESETS[name]
    except KeyError:
        raise ConfigError(
            f"unknown preset {name!r}; expected one of: {', '.join(PRESETS)}"
        ) from None
    if mode is None:
        return base
    settings = MODE_SETTINGS.get(name, {}).get(mode, {}) if isinstance(mode, str) else {}
    return base.replace(mode=mode, **settings)


def load_config_file(path: str | Path) -> dict[str, Any]:
    """Read a YAML or JSON mapping of config overrides.

    Raises:
        ConfigError: if the file is missing, unparsable or not a mapping.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"cannot read config file {path}: {exc.strerror}") from exc
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"config file {path} is not UTF-8 text (byte {exc.start}: {exc.reason})"
        ) from None
    try:
        data = json.loads(text) if path.suffix == ".json" else read_yaml(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        where = " ".join(str(exc).split())  # PyYAML's message spans lines
        raise ConfigError(f"cannot parse config file {path}: {where}") from exc
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"config file {path} must hold a mapping, got {type(data).__name__}")
    return data


def parse_override(item: str) -> tuple[str, Any]:
    """Parse one ``key=value`` override; the value is read as YAML (``3e-4``, ``[64, 64]``),
    and numbers separated by commas as a list, as the command line's own options write
    them (``obs_noise_max=0,0`` is ``[0, 0]``).

    Raises:
        ConfigError: if ``item`` has no ``=``.
    """
    key, sep, raw = item.partition("=")
    if not sep or not key.strip():
        raise ConfigError(f"override {item!r} must look like key=value")
    try:
        value = read_yaml(raw)
        if isinstance(value, str) and "," in value:
            parts = [read_yaml(part) for part in value.split(",")]
            if all(isinstance(p, int | float) and not isinstance(p, bool) for p in parts):
                value = parts
    except yaml.YAMLError as exc:
        raise ConfigError(f"cannot parse the value of override {item!r}: {exc}") from exc
    return key.strip(), value


def build_config(
    preset_name: str = DEFAULT_PRESET,
    config_file: str | Path | None = None,
    overrides: Mapping[str, Any] | None = None,
) -> TrainConfig:
    """Preset (for the mode the file or the overrides name, else the preset's), then file,
    then explicit overrides (later wins).

    Raises:
        ConfigError: on an unknown preset, mode, key or an invalid value.
    """
    chosen = load_config_file(config_file) if config_file is not None else {}
    chosen.update(overrides or {})
    data = preset(preset_name, chosen.get("mode", preset(preset_name).mode)).to_dict()
    data.update(chosen)
    return TrainConfig.from_dict(data)
