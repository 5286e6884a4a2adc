"""Config validation, presets, files, overrides and the saved configs."""

from __future__ import annotations

import json
import re
from importlib import resources
from pathlib import Path
from typing import Any

import pytest

from explaindrive.agent.config import (
    PAPER,
    ConfigError,
    TrainConfig,
    build_config,
    parse_override,
    preset,
)
from explaindrive.cli.train import resolve_config

SHIPPED_POLICIES = ("fast", "comfort")


def _card_config(name: str) -> dict[str, Any]:
    card = resources.files("explaindrive.agent") / "policies" / f"{name}.json"
    config: dict[str, Any] = json.loads(card.read_text(encoding="utf-8"))["config"]
    return config


def test_paper_preset_holds_the_paper_values() -> None:
    c = preset("paper")
    assert c.hidden_sizes == (128, 128)
    assert (c.lr, c.loss, c.buffer_size, c.batch_size, c.gamma) == (
        1e-3,
        "mse",
        5_000_000,
        64,
        0.99,
    )
    assert c.episodes == 11_000
    assert c.yellow_leader == "always"  # the paper's virtual leader at every yellow


def test_safe_preset_is_shorter_and_learns_the_shield() -> None:
    c = preset("safe")
    assert c.episodes < PAPER.episodes
    assert c.eps_decay_steps < PAPER.eps_decay_steps
    assert c.safe_learning and c.n_step == 3 and c.stop_when_safe == 200
    assert not PAPER.safe_learning and PAPER.n_step == 1 and PAPER.stop_when_safe is None
    assert c.yellow_leader == "decided"


def test_unknown_preset_and_key_are_rejected() -> None:
    with pytest.raises(ConfigError, match="unknown preset 'slow'"):
        preset("slow")
    with pytest.raises(ConfigError) as err:
        TrainConfig.from_dict({"lr_rate": 0.1})
    message = str(err.value)
    assert message.startswith("unknown training config key(s): lr_rate; known keys: batch_size,")
    assert "invalid" not in message  # nothing else is wrong
    with pytest.raises(ConfigError, match=r"^unknown training config key\(s\): lr_rate; "):
        TrainConfig(lr_rate=0.1)  # type: ignore[call-arg]
    with pytest.raises(ConfigError, match=r"^unknown training config key\(s\): lr_rate; "):
        PAPER.replace(lr_rate=0.1)


def test_unknown_keys_and_bad_values_are_reported_together() -> None:
    with pytest.raises(ConfigError) as err:
        TrainConfig.from_dict({"batchsize": 32, "episodes": 0, "gamma": 1.5})
    message = str(err.value)
    assert message.startswith("unknown training config key(s): batchsize; known keys: ")
    assert message.endswith(
        "; invalid training config: episodes: Input should be greater than 0, got 0; "
        "gamma: Input should be less than 1, got 1.5"
    )


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (
            {"mode": "stop"},
            "mode: must be one of fast, comfort, got 'stop' "
            "(stop is not a training mode: both agents learn it)",
        ),
        ({"mode": "sporty"}, "mode: must be one of fast, comfort, got 'sporty'"),
        ({"loss": "l1"}, "loss: must be one of mse, huber, got 'l1'"),
        ({"gamma": 1.0}, "gamma: Input should be less than 1, got 1.0"),
        ({"gamma": -0.1}, "gamma: Input should be greater than or equal to 0, got -0.1"),
        ({"batch_size": 0}, "batch_size: Input should be greater than 0, got 0"),
        ({"num_envs": 0}, "num_envs: Input should be greater than 0, got 0"),
        ({"tau": 0.0}, "tau: Input should be greater than 0, got 0.0"),
        ({"eps_final": 1.5}, "eps_final: Input should be less than or equal to 1, got 1.5"),
        ({"learning_starts": -1}, "learning_starts: Input should be greater than or equal to 0"),
        (
            {"stop_gap_s": [10, 5]},
            "stop_gap_s: must be [min, max] with 0 < min <= max, got [10.0, 5.0]",
        ),
        ({"stop_gap_s": [1, 2, 3]}, "stop_gap_s: Tuple should have at most 2 items"),
        ({"hidden_sizes": []}, "hidden_sizes: Value should have at least 1 item"),
        ({"hidden_sizes": [64, 0]}, "hidden_sizes.1: Input should be greater than 0, got 0"),
        ({"hidden_sizes": [64, 32.0]}, "hidden_sizes.1: Input should be a valid integer"),
        ({"traffic_levels": []}, "traffic_levels: Value should have at least 1 item"),
        (
            {"traffic_levels": [0.5, 2.5]},
            "traffic_levels.1: traffic level must be at most 2, got 2.5",
        ),
        ({"seed": -1}, "seed: seed must be an integer in [0, 2**31), got -1"),
        ({"lr": "fast"}, "lr: Input should be a valid number, got 'fast'"),
        ({"lr": float("nan")}, "lr: Input should be a finite number, got nan"),
        ({"episodes": 2.5}, "episodes: Input should be a valid integer, got 2.5"),
        ({"episodes": 2.0}, "episodes: Input should be a valid integer, got 2.0"),
        ({"episodes": "20"}, "episodes: Input should be a valid integer, got '20'"),
        ({"episodes": True}, "episodes: Input should be a valid integer, got True"),
        ({"save_replay": 1}, "save_replay: Input should be a valid boolean, got 1"),
        ({"save_replay": "yes"}, "save_replay: Input should be a valid boolean, got 'yes'"),
        ({"mode": 1}, "mode: Input should be a valid string, got 1"),
        (
            {"yellow_leader": "sometimes"},
            "yellow_leader: must be one of decided, gentle, always, got 'sometimes'",
        ),
        ({"batch_size": 128, "buffer_size": 64}, "batch_size (128) exceeds buffer_size (64)"),
    ],
)
def test_invalid_values_are_rejected(changes: dict[str, Any], message: str) -> None:
    with pytest.raises(ConfigError, match="^invalid training config: .*" + re.escape(message)):
        PAPER.replace(**changes)


def test_overrides_are_parsed_as_yaml_and_coerced() -> None:
    assert build_config("paper", overrides=dict([parse_override("lr=3e-4")])).lr == 3e-4
    assert parse_override("hidden_sizes=[64, 32]") == ("hidden_sizes", [64, 32])
    assert parse_override("obs_noise_max=0,0.5") == ("obs_noise_max", [0, 0.5])
    assert parse_override("name=a,b") == ("name", "a,b")  # text with a comma stays text
    c = build_config("passenger", overrides=dict([parse_override("obs_noise_max=0,0")]))
    assert c.obs_noise_max == (0.0, 0.0)
    c = build_config("paper", overrides=dict([parse_override("hidden_sizes=[64, 32]")]))
    assert c.hidden_sizes == (64, 32)
    assert PAPER.replace(lr=1).lr == 1.0 and isinstance(PAPER.replace(lr=1).lr, float)
    with pytest.raises(ConfigError, match="key=value"):
        parse_override("lr")


def test_config_file_then_overrides(tmp_path: Path) -> None:
    f = tmp_path / "c.yaml"
    f.write_text("batch_size: 32\nloss: huber\n")
    c = build_config("paper", f, {"batch_size": 16})
    assert (c.batch_size, c.loss, c.lr) == (16, "huber", 1e-3)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"batchsize": 32}))
    with pytest.raises(ConfigError, match=r"unknown training config key\(s\): batchsize"):
        build_config("safe", bad)
    with pytest.raises(ConfigError, match="cannot read config file"):
        build_config("safe", tmp_path / "missing.yaml")


def test_a_mode_gets_its_own_settings_before_file_and_overrides(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from explaindrive.agent import config

    settings = {"passenger": {"comfort": {"noisy_share": 0.0, "n_step_cut": True}}}
    monkeypatch.setattr(config, "MODE_SETTINGS", settings)
    comfort = preset("passenger", "comfort")
    assert (comfort.mode, comfort.noisy_share, comfort.n_step_cut) == ("comfort", 0.0, True)
    assert preset("passenger", "fast") == preset("passenger")  # fast: the preset itself
    assert preset("safe", "comfort") == preset("safe").replace(mode="comfort")
    c = build_config("passenger", None, {"mode": "comfort", "noisy_share": 0.25})
    assert (c.noisy_share, c.n_step_cut) == (0.25, True)  # an override wins
    f = tmp_path / "c.yaml"
    f.write_text("mode: comfort\n")
    assert build_config("passenger", f) == comfort  # the mode named in a file counts too
    assert build_config("passenger", f, {"mode": "fast"}) == preset("passenger")
    with pytest.raises(ConfigError, match="mode"):
        build_config("passenger", None, {"mode": ["comfort"]})


def test_json_round_trip() -> None:
    c = preset("safe").replace(num_envs=3, lr_final=None)
    assert TrainConfig.from_dict(json.loads(c.to_json())) == c
    assert c.envs == 3


def test_exponent_without_dot_is_a_number(tmp_path: Path) -> None:
    f = tmp_path / "c.yaml"
    f.write_text("lr: 3e-4\nlr_final: 1E-5\n")  # YAML 1.1 reads these as strings
    c = build_config("safe", f)
    assert (c.lr, c.lr_final) == (pytest.approx(3e-4), pytest.approx(1e-5))
    assert parse_override("eps_end=5e-2") == ("eps_end", 0.05)
    # an integer field still takes only integers: 1e6 is a float
    with pytest.raises(
        ConfigError, match=r"buffer_size: Input should be a valid integer, got 1000000.0"
    ):
        build_config("safe", overrides=dict([parse_override("buffer_size=1e6")]))
    with pytest.raises(ConfigError, match="lr: Input should be a valid number, got 'nan'"):
        build_config("safe", overrides={"lr": "nan"})


def test_configs_are_frozen() -> None:
    with pytest.raises(ValueError, match="frozen"):
        PAPER.lr = 0.1  # type: ignore[misc]
    assert PAPER.lr == 1e-3


ADDED_FIELDS = {
    "priority_alpha": 0.0, "priority_beta": 0.4, "priority_beta_steps": 400_000,
    "boundary_weight": 0.0, "boundary_margin": None, "limit_margin": None, "n_step_cut": False,
    "boundary_noise": False, "speed_noisy_share": None, "near_range_m": None,
    "speed_estimate": False, "stop_window_m": None, "speed_limiter": False,
}  # fmt: skip
"""Fields added after the shipped cards were written, with their defaults (uniform replay)."""


def _with_added_fields(saved: dict[str, Any]) -> dict[str, Any]:
    return {**{k: v for k, v in ADDED_FIELDS.items() if k not in saved}, **saved}


PRESET_CHANGED_SINCE: dict[str, dict[str, Any]] = {
    "fast": {"speed_limiter": False},
    "comfort": {"speed_limiter": False},
}
"""Per shipped card, the passenger preset's settings it was trained before (with their value
on the card)."""


@pytest.mark.parametrize("name", SHIPPED_POLICIES)
def test_shipped_cards_load_exactly(name: str) -> None:
    saved = _card_config(name)
    c = TrainConfig.from_dict(saved)
    saved = _with_added_fields(saved)
    assert c.to_dict() == saved
    # the same JSON, down to integers staying integers and floats floats
    assert c.to_json() == json.dumps(saved, indent=2, sort_keys=True)
    # the shipped networks are the passenger preset's, with their own seed
    assert c == preset("passenger", name).replace(
        num_envs=saved["num_envs"],
        seed=saved["seed"],
        episodes=1200,
        **PRESET_CHANGED_SINCE[name],
    )


@pytest.mark.parametrize("name", SHIPPED_POLICIES)
def test_resume_reads_the_saved_config_back_unchanged(name: str, tmp_path: Path) -> None:
    saved = _card_config(name)
    (tmp_path / "config.json").write_text(json.dumps(saved, indent=2, sort_keys=True))
    resumed = resolve_config(name, None, None, [], tmp_path, True)
    assert resumed == TrainConfig.from_dict(saved)
    assert resumed.to_dict() == _with_added_fields(saved)
