"""The shared config base: strict, frozen models that reject unknown keys."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import pytest
import yaml
from pydantic import PositiveInt, ValidationError, model_validator

from explaindrive.config import (
    FROM_LIST,
    ConfigError,
    ConfigModel,
    Seed,
    StrictModel,
    TextPath,
    TrafficLevel,
    read_yaml,
)
from explaindrive.validation import describe_errors


class Plain(StrictModel):
    count: int = 1
    rate: float = 0.5


class Knobs(ConfigModel):
    config_name = "knob config"

    count: PositiveInt = 1
    rate: float = 0.5
    on: bool = False
    name: str = "a"
    sizes: Annotated[tuple[int, ...], FROM_LIST] = (1, 2)
    path: TextPath | None = None
    level: TrafficLevel = 1.0
    seed: Seed = 0


def _error(**data: object) -> str:
    with pytest.raises(ConfigError) as err:
        Knobs(**data)  # type: ignore[arg-type]
    return str(err.value)


def test_strict_model_rejects_unknown_keys_with_pydantic_errors() -> None:
    with pytest.raises(ValidationError) as err:
        Plain(cuont=2)  # type: ignore[call-arg]
    assert describe_errors(err.value) == "cuont: Extra inputs are not permitted"


def test_unknown_keys_are_named_with_the_known_ones() -> None:
    assert _error(cuont=2, size=[3]) == (
        "unknown knob config key(s): cuont, size; "
        "known keys: count, level, name, on, path, rate, seed, sizes"
    )
    with pytest.raises(ConfigError, match=r"^unknown knob config key\(s\): cuont; "):
        Knobs.from_dict({"cuont": 2})


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"count": 2.0}, "count: Input should be a valid integer, got 2.0"),
        ({"count": "2"}, "count: Input should be a valid integer, got '2'"),
        ({"count": True}, "count: Input should be a valid integer, got True"),
        ({"count": 0}, "count: Input should be greater than 0, got 0"),
        ({"rate": "0.5"}, "rate: Input should be a valid number, got '0.5'"),
        ({"rate": False}, "rate: Input should be a valid number, got False"),
        ({"rate": float("inf")}, "rate: Input should be a finite number, got inf"),
        ({"on": 1}, "on: Input should be a valid boolean, got 1"),
        ({"on": "true"}, "on: Input should be a valid boolean, got 'true'"),
        ({"name": 3}, "name: Input should be a valid string, got 3"),
        ({"sizes": {1, 2}}, "sizes: Input should be a valid tuple"),
        ({"sizes": [1, 2.5]}, "sizes.1: Input should be a valid integer, got 2.5"),
        ({"level": 2.5}, "level: traffic level must be at most 2, got 2.5: on a busier road"),
        ({"seed": 2**31}, "seed: seed must be an integer in [0, 2**31), got 2147483648"),
    ],
)
def test_wrong_types_and_values_are_rejected_in_one_line(
    data: dict[str, object], message: str
) -> None:
    assert _error(**data).startswith(f"invalid knob config: {message}")


def test_accepted_inputs() -> None:
    k = Knobs(rate=1, sizes=[3, 4], path="x/y", level=1, seed=7)  # type: ignore[arg-type]
    assert (k.rate, k.sizes, k.path, k.level, k.seed) == (1.0, (3, 4), Path("x/y"), 1.0, 7)
    assert isinstance(k.rate, float) and isinstance(k.level, float)
    assert Knobs.from_dict(k.to_dict()) == k
    assert k.to_dict() == {
        "count": 1, "rate": 1.0, "on": False, "name": "a", "sizes": [3, 4], "path": "x/y",
        "level": 1.0, "seed": 7,
    }  # fmt: skip
    assert k.to_json().startswith('{\n  "count": 1,\n  "level": 1.0,')


def test_models_are_frozen_and_replace_validates() -> None:
    k = Knobs()
    with pytest.raises(ValidationError, match="Instance is frozen"):
        k.count = 3  # type: ignore[misc]
    with pytest.raises(ValidationError, match="Instance is frozen"):
        Plain().count = 3  # type: ignore[misc]
    assert k.replace(count=3).count == 3 and k.count == 1
    with pytest.raises(ConfigError, match="invalid knob config: count: Input should be greater"):
        k.replace(count=-3)
    with pytest.raises(ConfigError, match="a knob config must be a mapping, got list"):
        Knobs.from_dict([("count", 3)])  # type: ignore[arg-type]


def test_defaults_are_checked_too() -> None:
    class Broken(ConfigModel):
        count: PositiveInt = 0

    with pytest.raises(ConfigError, match="count: Input should be greater than 0, got 0"):
        Broken()


def test_whole_model_errors_are_the_message_alone() -> None:
    class Ordered(ConfigModel):
        config_name = "range"
        low: float = 0.0
        high: float = 1.0

        @model_validator(mode="after")
        def _ordered(self) -> Ordered:
            if self.low > self.high:
                raise ValueError(f"low ({self.low:g}) exceeds high ({self.high:g})")
            return self

    assert Ordered(low=0.5).low == 0.5
    with pytest.raises(ConfigError) as err:
        Ordered(low=2.0)
    assert str(err.value) == "invalid range: low (2) exceeds high (1)"


def test_yaml_reads_exponents_as_numbers() -> None:
    assert yaml.safe_load("3e-4") == "3e-4"  # YAML 1.1
    assert read_yaml("3e-4") == 3e-4
    assert read_yaml("[1E5, -2.5e-3, +1e2, .5e1]") == [1e5, -2.5e-3, 100.0, 5.0]
    assert read_yaml("a: 1\nb: 1.0\nc: 1e3x\nd: e5\ne: 0x10") == {
        "a": 1, "b": 1.0, "c": "1e3x", "d": "e5", "e": 16,
    }  # fmt: skip
    assert yaml.safe_load("3e-4") == "3e-4"  # the safe loader itself is unchanged


def test_error_lines_quote_short_inputs_and_validator_messages_as_they_are() -> None:
    class Record(StrictModel):
        speed_mps: float = 0.0
        label: str = ""
        level: TrafficLevel = 1.0

    with pytest.raises(ValidationError) as err:
        Record(speed_mps="x" * 80, label=None, level=0)  # type: ignore[arg-type]
    assert describe_errors(err.value) == (
        "speed_mps: Input should be a valid number; "
        "label: Input should be a valid string, got None; "
        "level: traffic level must be > 0, got 0"
    )
