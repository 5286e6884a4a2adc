"""ExplainDrive: passenger-directed, explainable autonomous driving in SUMO."""

from __future__ import annotations

from explaindrive.commands import Command

__all__ = ["ENV_ID", "Command", "__version__"]

__version__ = "0.1.0"

ENV_ID = "explaindrive/UrbanDrive-v0"


def _register() -> None:
    from gymnasium.envs.registration import register, registry

    if ENV_ID not in registry:
        register(id=ENV_ID, entry_point="explaindrive.env.urban_drive:UrbanDriveEnv")


_register()
