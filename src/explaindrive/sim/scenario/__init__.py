"""The urban scenario family: its parameters, layout, how it is built, and its files.

Names are imported lazily: :mod:`explaindrive.config` reads the shared ranges from
:mod:`explaindrive.sim.scenario.limits` while the layout itself needs the config layer.
"""

from typing import Any

__all__ = ["ScenarioFiles", "default_scenario"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from explaindrive.sim.scenario import files

        return getattr(files, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
