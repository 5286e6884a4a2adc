"""Config validation, presets, files and overrides."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from explaindrive.agent.config import (
    PAPER,
    ConfigError,
    TrainConfig,
    build_config,
    parse_override,
    preset,
)


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


def test_safe_preset_is_shorter_and_learns_the_shield() -> None:
    c = preset("safe")
    assert c.episodes < PAPER.episodes
    assert c.eps_decay_steps < PAPER.eps_decay_steps
    assert c.safe_learning and c.n_step == 3 and c.stop_when_safe == 200
    assert not PAPER.safe_learning and PAPER.n_step == 1 and PAPER.stop_when_safe is None


def test_unknown_preset_and_key_are_rejected() -> None:
    with pytest.raises(ConfigError, match="unknown preset 'slow'"):
        preset("slow")
    with pytest.raises(ConfigError, match=r"unknown config key.*lr_rate"):
        TrainConfig.from_dict({"lr_rate": 0.1})


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"mode": "stop"}, "stop is not a training mode"),
        ({"mode": "sporty"}, "mode must be one of fast, comfort"),
        ({"gamma": 1.0}, "gamma must be in"),
        ({"batch_size": 0}, "batch_size must be > 0"),
        ({"tau": 0.0}, "tau must be in"),
        ({"stop_gap_s": [10, 5]}, "stop_gap_s must be"),
        ({"hidden_sizes": []}, "hidden_sizes"),
        ({"lr": "fast"}, "'lr' must be a number"),
        ({"episodes": 2.5}, "'episodes' must be an integer"),
        ({"save_replay": 1}, "'save_replay' must be true/false"),
        ({"stop_gap_s": [1, 2, 3]}, "must have 2 items"),
    ],
)
def test_invalid_values_are_rejected(changes: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        PAPER.replace(**changes)


def test_overrides_are_parsed_as_yaml_and_coerced() -> None:
    assert build_config("paper", overrides=dict([parse_override("lr=3e-4")])).lr == 3e-4
    assert parse_override("hidden_sizes=[64, 32]") == ("hidden_sizes", [64, 32])
    c = build_config("paper", overrides=dict([parse_override("hidden_sizes=[64, 32]")]))
    assert c.hidden_sizes == (64, 32)
    assert PAPER.replace(lr=1).lr == 1.0
    with pytest.raises(ConfigError, match="key=value"):
        parse_override("lr")


def test_config_file_then_overrides(tmp_path: Path) -> None:
    f = tmp_path / "c.yaml"
    f.write_text("batch_size: 32\nloss: huber\n")
    c = build_config("paper", f, {"batch_size": 16})
    assert (c.batch_size, c.loss, c.lr) == (16, "huber", 1e-3)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"batchsize": 32}))
    with pytest.raises(ConfigError, match="batchsize"):
        build_config("safe", bad)
    with pytest.raises(ConfigError, match="cannot read config file"):
        build_config("safe", tmp_path / "missing.yaml")


def test_json_round_trip() -> None:
    c = preset("safe").replace(num_envs=3, lr_final=None)
    assert TrainConfig.from_dict(json.loads(c.to_json())) == c
    assert c.envs == 3


def test_exponent_without_dot_is_a_number(tmp_path: Path) -> None:
    f = tmp_path / "c.yaml"
    f.write_text("lr: 3e-4\n")  # YAML 1.1 reads this as a string
    assert build_config("safe", f).lr == pytest.approx(3e-4)
    with pytest.raises(ConfigError, match="'lr' must be a number"):
        build_config("safe", overrides={"lr": "nan"})
