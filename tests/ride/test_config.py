"""RideConfig rejects bad settings with a message that names them."""

from __future__ import annotations

import pytest

from explaindrive.ride.config import RideConfig


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"max_steps": 0}, "max_steps must be > 0, got 0"),
        ({"seed": -1}, r"seed must be an integer in \[0, 2\*\*31\), got -1"),
        ({"seed": 2**31}, r"seed must be an integer in \[0, 2\*\*31\)"),
        (
            {"interpret_deadline_s": -0.5},
            "interpret_deadline_s must be a finite number >= 0, got -0.5",
        ),
        ({"explanation_cooldown_s": -1.0}, "explanation_cooldown_s must be a finite number >= 0"),
        (
            {"explanation_cooldown_s": float("nan")},
            "explanation_cooldown_s must be a finite number >= 0, got nan",
        ),
        (
            {"audio_deadline_s": float("inf")},
            "audio_deadline_s must be a finite number >= 0, got inf",
        ),
        ({"traffic_level": float("nan")}, "traffic level must be a finite number > 0, got nan"),
        (
            {"traffic_level": 99.0},
            "traffic level must be at most 1.75, got 99: on a busier road the ego cannot enter",
        ),
        ({"backend": "gpt"}, "unknown language backend 'gpt'; choose one of: embedded, openai"),
        ({"traffic_level": 0.0}, "traffic level must be > 0"),
    ],
)
def test_bad_settings_are_rejected(settings: dict[str, object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        RideConfig(**settings)  # type: ignore[arg-type]


def test_defaults_and_accepted_edges() -> None:
    cfg = RideConfig(seed=2**31 - 1, explain_deadline_s=0.0, backend="openai", traffic_level=1.5)
    assert (cfg.max_steps, cfg.interpret_deadline_s, cfg.backend) == (600, 2.0, "openai")
