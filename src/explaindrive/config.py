"""The one way a config is declared: a frozen pydantic model that rejects unknown keys.

:class:`StrictModel` fixes the rules every config follows. A key the model does not
declare is an error, a built config cannot be changed, defaults are checked like given
values and every number must be finite. Values are checked strictly: an integer field
takes only integers (``2.0``, ``"2"`` and ``true`` are errors), a float field takes
integers and floats, a flag only ``true``/``false`` and a text field only text. Tuples
are given as lists in JSON and YAML (:data:`FROM_LIST`) and paths as text (:data:`TextPath`).

:class:`LaxModel` keeps every rule but converts values as pydantic's lax mode does, for
input written by hand. :class:`ConfigModel` adds what the run settings (training, env, ride)
share: a :class:`ConfigError` whose one line names every bad key (:func:`config_error`),
:meth:`~ConfigModel.from_dict`, a validated :meth:`~ConfigModel.replace` and JSON-ready
:meth:`~ConfigModel.to_dict`. :data:`TrafficLevel` and :data:`Seed` check a value against
the scenario's one definition of its range (:mod:`explaindrive.sim.scenario.limits`).
"""

from __future__ import annotations

import functools
import json
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, ClassVar, Self

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
)

from explaindrive.sim.scenario.limits import validate_seed, validate_traffic_level
from explaindrive.validation import describe_error


class ConfigError(ValueError):
    """A configuration value, key or file is invalid."""


class StrictModel(BaseModel):
    """Base of every config: frozen, unknown keys rejected, values checked strictly.

    Invalid input raises pydantic's :class:`~pydantic.ValidationError`; see
    :class:`ConfigModel` for one-line :class:`ConfigError` messages.
    """

    model_config = ConfigDict(
        extra="forbid",
        frozen=True,
        strict=True,
        allow_inf_nan=False,
        validate_default=True,
        use_attribute_docstrings=True,
    )


class LaxModel(StrictModel):
    """A :class:`StrictModel` whose values are converted as pydantic's lax mode does: paths
    and numbers given as text, ``2.0`` for an integer. For input a person writes by hand (a
    language config, a ride script, a request body); the other rules are :class:`StrictModel`'s.
    """

    model_config = ConfigDict(strict=False)


class ConfigModel(StrictModel):
    """A :class:`StrictModel` whose invalid input raises one-line :class:`ConfigError`."""

    config_name: ClassVar[str] = "config"
    """What the config is called in its error messages (``training config``...)."""

    def __init__(self, /, **data: Any) -> None:
        """Validate ``data``.

        Raises:
            ConfigError: naming every unknown key and every invalid value.
        """
        try:
            super().__init__(**data)
        except ValidationError as exc:
            raise config_error(exc, type(self)) from None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Self:
        """Build a config from a mapping of its fields (lists stand for tuples).

        Raises:
            ConfigError: naming every unknown key and every invalid value.
        """
        if not isinstance(data, Mapping):
            raise ConfigError(f"a {cls.config_name} must be a mapping, got {type(data).__name__}")
        # not model_validate: it calls __init__ and wraps its ConfigError in a ValidationError
        return cls(**{str(key): value for key, value in data.items()})

    def replace(self, **changes: Any) -> Self:
        """A copy with some fields changed, validated like :meth:`from_dict`.

        Raises:
            ConfigError: naming every unknown key and every invalid value.
        """
        return self.from_dict({**self.model_dump(), **changes})

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: tuples become lists and paths text."""
        return self.model_dump(mode="json")

    def to_json(self) -> str:
        """The config as indented JSON with sorted keys."""
        return json.dumps(self.to_dict(), indent=2, sort_keys=True)


def config_error(exc: ValidationError, model: type[ConfigModel]) -> ConfigError:
    """A :class:`ConfigError` whose one line names every problem ``exc`` found in a ``model``.

    Unknown keys come first, with the keys ``model`` knows:
    ``"unknown env config key(s): max_step; known keys: cache_dir, ...; invalid env
    config: warmup_s: Input should be a valid integer, got 1.5"``.
    """
    unknown: list[str] = []
    invalid: list[str] = []
    for error in exc.errors():
        if error["type"] == "extra_forbidden" and len(error["loc"]) == 1:
            unknown.append(str(error["loc"][0]))
        else:
            invalid.append(describe_error(error, root=""))
    parts = []
    if unknown:
        parts.append(
            f"unknown {model.config_name} key(s): {', '.join(unknown)}; "
            f"known keys: {', '.join(sorted(model.model_fields))}"
        )
    if invalid:
        parts.append(f"invalid {model.config_name}: " + "; ".join(invalid))
    return ConfigError("; ".join(parts))


def _tuple_from_list(value: object) -> object:
    return tuple(value) if isinstance(value, list) else value


FROM_LIST = BeforeValidator(_tuple_from_list)
"""Marks a tuple field that also takes a list, as JSON and YAML give it (``Annotated[tuple[int,
...], FROM_LIST]``); a set, whose order is arbitrary, stays an error."""

TextPath = Annotated[Path, Field(strict=False)]
"""A path, also given as text."""

TrafficLevel = Annotated[float, BeforeValidator(validate_traffic_level)]
"""A traffic level in (0, :data:`~explaindrive.sim.scenario.limits.MAX_TRAFFIC_LEVEL`]."""

Seed = Annotated[int, BeforeValidator(validate_seed)]
"""A simulation seed in [0, :data:`~explaindrive.sim.scenario.limits.SEED_LIMIT`)."""


def one_of(choices: tuple[str, ...]) -> AfterValidator:
    """A validator accepting only the names in ``choices``."""

    def check(value: str) -> str:
        if value not in choices:
            raise ValueError(f"must be one of {', '.join(choices)}, got {value!r}")
        return value

    return AfterValidator(check)


@functools.cache
def _loader() -> type:
    """YAML as PyYAML reads it, except that ``1e-3`` (an exponent, no dot) is a number (built
    on first use: a command's ``--help`` does not import PyYAML)."""
    import yaml

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_implicit_resolver(
        "tag:yaml.org,2002:float",
        re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
        list("-+0123456789."),
    )
    return Loader


def read_yaml(text: str) -> Any:
    """Parse YAML text; unlike YAML 1.1, numbers such as ``3e-4`` are read as floats.

    Raises:
        yaml.YAMLError: if the text is not valid YAML.
    """
    import yaml

    return yaml.load(text, Loader=_loader())  # a SafeLoader
