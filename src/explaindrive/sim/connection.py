"""One SUMO simulation: libsumo in-process by default, TraCI (for sumo-gui) on request.

libsumo runs one simulation per process; :class:`SumoConnection` guards that
and gives a clear error instead of SUMO's own crash.
"""

from __future__ import annotations

import logging
from types import ModuleType
from typing import Any, ClassVar

from explaindrive.sim.sumo_home import sumo_binary, sumo_home

log = logging.getLogger(__name__)


class SumoConnectionError(RuntimeError):
    """SUMO could not be started or was used wrongly."""


class SumoConnection:
    """Owns a running SUMO simulation.

    Args:
        gui: run ``sumo-gui`` through TraCI instead of libsumo.
    """

    _libsumo_owner: ClassVar[SumoConnection | None] = None

    def __init__(self, gui: bool = False) -> None:
        self.gui = gui
        self._api: ModuleType | None = None

    @property
    def api(self) -> Any:
        """The ``libsumo`` or ``traci`` module of the running simulation."""
        if self._api is None:
            raise SumoConnectionError("the simulation is not running")
        return self._api

    @property
    def running(self) -> bool:
        """Whether a simulation is running."""
        return self._api is not None

    def start_or_load(self, args: list[str]) -> None:
        """Start SUMO with ``args`` (options only, no binary), or reload it if running."""
        sumo_home()
        if self._api is not None:
            self._api.load(args)
            return
        if self.gui:
            import traci

            traci.start([sumo_binary("sumo-gui"), *args, "--start", "--quit-on-end"])
            self._api = traci
            return
        owner = SumoConnection._libsumo_owner
        if owner is not None and owner is not self:
            raise SumoConnectionError(
                "libsumo allows one simulation per process and another environment in this "
                "process is running one; close it first or use a vector env with one "
                "process per environment"
            )
        import libsumo

        try:
            libsumo.start([sumo_binary("sumo"), *args])
        except Exception as exc:  # libsumo raises its own TraCIException
            # SUMO's messages span lines ("... not known.\n The route can not be build.")
            message = " ".join(str(exc).split())
            raise SumoConnectionError(f"SUMO failed to start: {message}") from exc
        SumoConnection._libsumo_owner = self
        self._api = libsumo

    def close(self) -> None:
        """Stop the simulation (idempotent)."""
        if self._api is None:
            return
        try:
            self._api.close()
        except Exception as exc:  # closing a dead connection must not mask the real error
            log.debug("ignoring error while closing SUMO: %s", exc)
        finally:
            if SumoConnection._libsumo_owner is self:
                SumoConnection._libsumo_owner = None
            self._api = None
