"""RideConfig rejects bad settings with a message that names them."""

from __future__ import annotations

import re

import pytest

from explaindrive.config import ConfigError
from explaindrive.ride.config import RideConfig
from explaindrive.sim.scenario.layout import MAX_TRAFFIC_LEVEL, SEED_LIMIT


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"max_steps": 0}, "max_steps: Input should be greater than 0, got 0"),
        ({"max_steps": 10.0}, "max_steps: Input should be a valid integer, got 10.0"),
        ({"seed": -1}, "seed: seed must be an integer in [0, 2**31), got -1"),
        ({"seed": SEED_LIMIT}, "seed: seed must be an integer in [0, 2**31), got 2147483648"),
        ({"seed": 1.0}, "seed: seed must be an integer in [0, 2**31), got 1.0"),
        (
            {"interpret_deadline_s": -0.5},
            "interpret_deadline_s: Input should be greater than or equal to 0, got -0.5",
        ),
        (
            {"explanation_cooldown_s": -1.0},
            "explanation_cooldown_s: Input should be greater than or equal to 0, got -1.0",
        ),
        (
            {"explanation_cooldown_s": float("nan")},
            "explanation_cooldown_s: Input should be a finite number, got nan",
        ),
        (
            {"audio_deadline_s": float("inf")},
            "audio_deadline_s: Input should be a finite number, got inf",
        ),
        (
            {"traffic_level": float("nan")},
            "traffic_level: traffic level must be a finite number > 0, got nan",
        ),
        (
            {"traffic_level": 99.0},
            "traffic_level: traffic level must be at most 2, got 99: "
            "on a busier road the ego cannot enter",
        ),
        ({"traffic_level": 0.0}, "traffic_level: traffic level must be > 0, got 0"),
        (
            {"backend": "gpt"},
            "backend: unknown language backend 'gpt'; choose one of: embedded, openai",
        ),
        ({"realtime": 1}, "realtime: Input should be a valid boolean, got 1"),
        (
            {"obs_noise": (1.0, 9.0)},
            "obs_noise: speed noise must be in [0, 5.0] m/s, got 9.0",
        ),
    ],
)
def test_bad_settings_are_rejected(settings: dict[str, object], message: str) -> None:
    with pytest.raises(ConfigError, match=f"^invalid ride config: {re.escape(message)}$"):
        RideConfig(**settings)  # type: ignore[arg-type]


def test_unknown_setting_is_named() -> None:
    with pytest.raises(ConfigError) as err:
        RideConfig(max_step=10)  # type: ignore[call-arg]
    assert str(err.value).startswith("unknown ride config key(s): max_step; known keys: ")
    assert "max_steps" in str(err.value)


def test_every_problem_is_reported_at_once() -> None:
    with pytest.raises(ConfigError) as err:
        RideConfig(max_steps=0, seed=-1)
    assert str(err.value) == (
        "invalid ride config: seed: seed must be an integer in [0, 2**31), got -1; "
        "max_steps: Input should be greater than 0, got 0"
    )


def test_defaults_and_accepted_edges() -> None:
    cfg = RideConfig(
        seed=SEED_LIMIT - 1,
        explain_deadline_s=0,
        backend="openai",
        traffic_level=MAX_TRAFFIC_LEVEL,
    )
    assert (cfg.max_steps, cfg.interpret_deadline_s, cfg.backend) == (600, 4.0, "openai")
    assert (cfg.decide_deadline_s, cfg.explain_deadline_s) == (4.0, 0.0)
    assert (cfg.seed, cfg.explain_deadline_s, cfg.traffic_level) == (2**31 - 1, 0.0, 2.0)
    assert RideConfig(traffic_level=1).traffic_level == 1.0
    assert cfg.replace(seed=3) == RideConfig.from_dict({**cfg.to_dict(), "seed": 3})
