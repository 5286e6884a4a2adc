"""ExplainDrive: passenger-directed, explainable autonomous driving in SUMO.

The names a researcher needs, each imported on first use (``import explaindrive`` loads
neither torch nor Gymnasium):

- the scenario: :class:`ScenarioParams`, :class:`ScenarioFiles`, :func:`default_scenario`,
  :func:`random_scenario`;
- the environment: :data:`ENV_ID`, :class:`UrbanDriveEnv`, :class:`EnvConfig`,
  :class:`Command`;
- the agents: :func:`load_policy`, :class:`QPolicy`, :class:`MergedController`;
- the evaluation: :class:`EpisodeSpec`, :class:`PolicySpec`, :func:`run_episode`;
- the language stack (extra ``[language]``): :class:`LanguageStack`,
  :func:`make_language_stack`, :class:`LanguageConfig`, :class:`Transcriber`;
- the ride (extra ``[language]``): :class:`RideSession`, :class:`RideConfig`.

``gymnasium.make("explaindrive/UrbanDrive-v0")`` works once ``explaindrive`` is imported:
the id is registered when Gymnasium loads, or at once if it is already loaded.
"""

from __future__ import annotations

import importlib
import sys
from types import ModuleType
from typing import TYPE_CHECKING, Any

from explaindrive.commands import Command

if TYPE_CHECKING:
    from collections.abc import Sequence
    from importlib.machinery import ModuleSpec

__version__ = "0.1.0"

ENV_ID = "explaindrive/UrbanDrive-v0"
ENTRY_POINT = "explaindrive.env.urban_drive:UrbanDriveEnv"

# public name -> the module that defines it
_LAZY: dict[str, str] = {
    "ScenarioParams": "explaindrive.sim.scenario.params",
    "ScenarioFiles": "explaindrive.sim.scenario.files",
    "default_scenario": "explaindrive.sim.scenario.files",
    "random_scenario": "explaindrive.sim.scenario.directory",
    "UrbanDriveEnv": "explaindrive.env.urban_drive",
    "EnvConfig": "explaindrive.env.config",
    "load_policy": "explaindrive.agent.checkpoint",
    "QPolicy": "explaindrive.agent.controller",
    "MergedController": "explaindrive.agent.controller",
    "EpisodeSpec": "explaindrive.evaluation.spec",
    "PolicySpec": "explaindrive.evaluation.spec",
    "run_episode": "explaindrive.evaluation.runner",
    "LanguageStack": "explaindrive.language.stack",
    "make_language_stack": "explaindrive.language.stack",
    "LanguageConfig": "explaindrive.language.config",
    "Transcriber": "explaindrive.language.speech.transcriber",
    "RideSession": "explaindrive.ride.session",
    "RideConfig": "explaindrive.ride.config",
}

__all__ = ["ENV_ID", "Command", "__version__", *_LAZY]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    try:
        value = getattr(importlib.import_module(module), name)
    except ModuleNotFoundError as exc:
        from explaindrive.extras import missing_extra

        missing = missing_extra(exc, f"explaindrive.{name}")
        if missing is None:
            raise
        raise missing from None
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


def _register_env(registration: ModuleType) -> None:
    """Register :data:`ENV_ID` in Gymnasium's ``registration`` module."""
    if ENV_ID not in registration.registry:
        registration.register(id=ENV_ID, entry_point=ENTRY_POINT)


class _RegisterWithGymnasium:
    """Registers :data:`ENV_ID` right after ``gymnasium.envs.registration`` loads (a
    :class:`importlib.abc.MetaPathFinder`, without importing :mod:`importlib.abc`)."""

    target = "gymnasium.envs.registration"

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if fullname != self.target:
            return None
        sys.meta_path.remove(self)
        for finder in sys.meta_path:
            spec = finder.find_spec(fullname, path, target)
            if spec is not None and spec.loader is not None:
                break
        else:
            return None
        exec_module = spec.loader.exec_module

        def exec_and_register(module: ModuleType) -> None:
            exec_module(module)
            _register_env(module)

        spec.loader.exec_module = exec_and_register  # type: ignore[method-assign]
        return spec


def _register() -> None:
    if _RegisterWithGymnasium.target in sys.modules:
        _register_env(sys.modules[_RegisterWithGymnasium.target])
    elif not any(isinstance(f, _RegisterWithGymnasium) for f in sys.meta_path):
        sys.meta_path.insert(0, _RegisterWithGymnasium())


_register()
