"""EnvConfig: defaults, accepted inputs and one-line errors (no SUMO needed)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from explaindrive.config import ConfigError
from explaindrive.env.config import EGO_MODELS, EnvConfig


def test_defaults() -> None:
    c = EnvConfig()
    assert (c.traffic_level, c.max_steps, c.warmup_s, c.insert_timeout_s) == (1.0, 1000, 180, 60)
    assert (c.normalize_obs, c.net_file, c.cache_dir, c.ego_model) == (False, None, None, "agent")
    assert EGO_MODELS == ("agent", "krauss", "idm")


def test_paths_may_be_given_as_text() -> None:
    c = EnvConfig(net_file="a/b.net.xml", cache_dir=Path("/tmp/cache"))  # type: ignore[arg-type]
    assert c.net_file == Path("a/b.net.xml") and isinstance(c.net_file, Path)
    assert c.to_dict()["net_file"] == "a/b.net.xml"
    assert EnvConfig.from_dict(c.to_dict()) == c


def test_unknown_key_is_named() -> None:
    with pytest.raises(ConfigError) as err:
        EnvConfig.from_mapping({"max_step": 10})
    assert str(err.value) == (
        "unknown env config key(s): max_step; known keys: cache_dir, demand_file, ego_model, "
        "insert_timeout_s, max_steps, net_file, normalize_obs, obs_noise, reward, route, "
        "scenario, scenario_every, scenario_paper_share, speed_limiter, stop_window_m, "
        "traffic_level, warmup_s, "
        "yellow_leader"
    )
    with pytest.raises(ConfigError, match=r"^unknown env config key\(s\): trafic_level; "):
        EnvConfig().replace(trafic_level=0.5)


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"traffic_level": -1.0}, "traffic_level: traffic level must be > 0, got -1"),
        ({"traffic_level": True}, "traffic_level: traffic level must be a finite number > 0"),
        ({"max_steps": 0}, "max_steps: Input should be greater than 0, got 0"),
        ({"max_steps": 5.0}, "max_steps: Input should be a valid integer, got 5.0"),
        ({"insert_timeout_s": True}, "insert_timeout_s: Input should be a valid integer, got True"),
        ({"warmup_s": -1}, "warmup_s: Input should be greater than or equal to 0, got -1"),
        ({"normalize_obs": "yes"}, "normalize_obs: Input should be a valid boolean, got 'yes'"),
        (
            {"ego_model": "wiedemann"},
            "ego_model: must be one of agent, krauss, idm, got 'wiedemann'",
        ),
        ({"net_file": 3}, "net_file: Input is not a valid path"),
        (
            {"yellow_leader": "never"},
            "yellow_leader: must be one of decided, gentle, always, got 'never'",
        ),
    ],
)
def test_bad_settings_are_rejected(settings: dict[str, object], message: str) -> None:
    with pytest.raises(ConfigError, match="^invalid env config: " + re.escape(message)):
        EnvConfig(**settings)  # type: ignore[arg-type]


def test_replace_checks_the_changes_and_keeps_the_rest() -> None:
    c = EnvConfig(traffic_level=0.5, ego_model="krauss")
    d = c.replace(max_steps=20)
    assert (d.traffic_level, d.ego_model, d.max_steps) == (0.5, "krauss", 20)
    assert c.max_steps == 1000
    with pytest.raises(ConfigError, match="warmup_s: Input should be a valid integer"):
        c.replace(warmup_s=1.5)
