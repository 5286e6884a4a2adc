"""The SUMO side of an episode: start or reload SUMO at the cached warm-up, let the ego in,
advance one step and read what happened to it.

:class:`SumoProcess` owns the simulation. It knows nothing of observations or rewards: it
returns the ego's entry (:class:`EgoEntry`) and each step's :class:`Motion`.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import traci.constants as tc

from explaindrive.env import state as S
from explaindrive.env.violations import ego_collided
from explaindrive.env.warm_start import restore_warm_state, sumo_args
from explaindrive.sim.connection import SumoConnection
from explaindrive.sim.route import RouteCrossing
from explaindrive.sim.scenario.files import (
    BASELINE_EGO_TYPES,
    EGO_ID,
    EGO_ROUTE_ID,
    EGO_TYPE_ID,
    ScenarioFiles,
)

log = logging.getLogger(__name__)

EGO_VARS = (tc.VAR_SPEED, tc.VAR_DISTANCE, tc.VAR_LEADER, tc.VAR_LANE_ID, tc.VAR_LANEPOSITION)
SIM_VARS = (tc.VAR_ARRIVED_VEHICLES_IDS, tc.VAR_COLLIDING_VEHICLES_IDS)
ENTRY_CLEAR_AFTER_S = 10  # [s] the entry stretch is cleared after every such wait for a gap
ENTRY_CLEAR_M = 30.0  # [m] length of that stretch
BACKLOG_DROP_AFTER_S = 30  # [s] after this wait the vehicles queued to enter there go too
STRATEGIC_LANE_CHANGES = 0b011000000001  # SUMO lane-change mode: strategic changes only
SUMO_DRIVES = -1.0  # [m/s] the speed that hands the ego's speed back to SUMO


@dataclass(frozen=True, slots=True)
class EgoEntry:
    """The ego as it entered.

    Attributes:
        start_pos_m: its front's position on its first lane [m].
        min_gap_m: its vType's minGap [m] (SUMO reports leader gaps minus it).
        length_m: its length [m].
    """

    start_pos_m: float
    min_gap_m: float
    length_m: float


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class Motion:
    """Outcome of one simulated step for the ego.

    Attributes:
        speed_mps: its speed after the step (the set speed once it has left).
        collided: it collided during the step.
        arrived: it reached the end of its route.
        ego: its subscription results; ``None`` once it has left the simulation.
    """

    speed_mps: float
    collided: bool
    arrived: bool
    ego: Any


class SumoProcess:
    """The running simulation of an environment.

    Args:
        gui: run sumo-gui over TraCI instead of libsumo.
        ego_model: ``"agent"`` (speed set each step, SUMO's checks off) or a SUMO baseline.
        insert_timeout_s: how long the ego may wait for space to enter [s].
    """

    def __init__(self, gui: bool, ego_model: str, insert_timeout_s: int) -> None:
        self._conn = SumoConnection(gui=gui)
        self.ego_model = ego_model
        self.insert_timeout_s = insert_timeout_s

    @property
    def api(self) -> Any:
        """The running ``libsumo``/``traci`` module."""
        return self._conn.api

    def new_network(self) -> None:
        """Forget what was read from the current network and stop SUMO: the next episode
        starts it on another network."""
        self._conn.close()

    def close(self) -> None:
        """Stop SUMO (idempotent)."""
        self._conn.close()

    def start_episode(
        self,
        scenario: ScenarioFiles,
        crossings: tuple[RouteCrossing, ...],
        level: float,
        seed: int,
        warmup_s: int,
        drop_backlog: bool,
    ) -> EgoEntry:
        """Start (or reload) SUMO at the warm-up state of (scenario, level, seed) and let the
        ego in.

        Raises:
            RuntimeError: if the warm-up fails or the ego cannot enter in time.
        """
        self._conn.start_or_load(sumo_args(scenario, level, seed))
        restore_warm_state(self._conn.api, scenario, level, seed, warmup_s)
        return self._insert_ego(scenario, crossings, drop_backlog)

    def advance(
        self, set_speed_mps: float, planned_speed_mps: float, before_step: Callable[[Any], None]
    ) -> Motion:
        """Set the ego's speed (:data:`SUMO_DRIVES` lets SUMO choose it), call
        ``before_step(api)``, simulate one step and read the ego's outcome.

        ``speed_mps`` of the result is SUMO's reading or, once the ego has left,
        ``planned_speed_mps``.
        """
        api = self._conn.api
        api.vehicle.setSpeed(EGO_ID, set_speed_mps)
        before_step(api)
        api.simulationStep()
        sim = api.simulation.getSubscriptionResults()
        collided = bool(sim.get(tc.VAR_COLLIDING_VEHICLES_IDS)) and ego_collided(api)
        arrived = not collided and EGO_ID in sim.get(tc.VAR_ARRIVED_VEHICLES_IDS, ())
        ego = None
        if not collided and not arrived:
            ego = api.vehicle.getSubscriptionResults(EGO_ID)
        speed = float(ego[tc.VAR_SPEED]) if ego is not None else planned_speed_mps
        return Motion(speed, collided, arrived, ego)

    def ego_state(self) -> Any:
        """The ego's subscription results of the current step."""
        return self._conn.api.vehicle.getSubscriptionResults(EGO_ID)

    def _insert_ego(
        self, scenario: ScenarioFiles, crossings: tuple[RouteCrossing, ...], drop_backlog: bool
    ) -> EgoEntry:
        """Add the ego, wait for it to enter and subscribe to what the episode reads."""
        api = self._conn.api
        model = self.ego_model
        type_id = EGO_TYPE_ID if model == "agent" else BASELINE_EGO_TYPES[model]
        api.vehicle.add(
            EGO_ID,
            EGO_ROUTE_ID,
            typeID=type_id,
            depart="now",
            departLane="best",
            departPos="base",
            departSpeed="0",
        )
        for waited in range(self.insert_timeout_s):
            api.simulationStep()
            if EGO_ID in api.simulation.getDepartedIDList():
                break
            if waited and waited % ENTRY_CLEAR_AFTER_S == 0:
                self._clear_entry(
                    scenario.route_edges[0], drop_backlog or waited >= BACKLOG_DROP_AFTER_S
                )
        else:
            raise RuntimeError(
                f"the ego could not enter within {self.insert_timeout_s} s "
                "(the first road stays blocked); lower the traffic level"
            )
        lane_changes = STRATEGIC_LANE_CHANGES if scenario.strategic_lane_changes else 0
        api.vehicle.setLaneChangeMode(EGO_ID, lane_changes)
        min_gap_m = float(api.vehicle.getMinGap(EGO_ID))
        length_m = float(api.vehicle.getLength(EGO_ID))
        if model == "agent":
            api.vehicle.setSpeedMode(EGO_ID, 0)  # no car-following, light or right-of-way checks
            api.vehicle.setSpeed(EGO_ID, 0.0)
        api.vehicle.subscribe(EGO_ID, EGO_VARS, parameters={tc.VAR_LEADER: S.SENSOR_RANGE_M})
        api.simulation.subscribe(SIM_VARS)
        for crossing in crossings:
            for edge in (crossing.crossing_edge, *crossing.walkingareas):
                api.edge.subscribe(edge, (tc.LAST_STEP_PERSON_ID_LIST,))
        start_pos_m = float(api.vehicle.getLanePosition(EGO_ID))
        return EgoEntry(start_pos_m, min_gap_m, length_m)

    def _clear_entry(self, edge: str, drop_backlog: bool) -> None:
        """Remove background vehicles from the ego's entry stretch on ``edge`` (oversaturated
        demand), and with ``drop_backlog`` those still waiting to enter there, which SUMO
        would insert before the ego."""
        api = self._conn.api
        if drop_backlog:
            for vid in api.simulation.getPendingVehicles():
                if vid != EGO_ID and api.vehicle.getRoute(vid)[0] == edge:
                    api.vehicle.remove(vid)
        lanes = [f"{edge}_{i}" for i in range(api.edge.getLaneNumber(edge))]
        for vid in (v for lane in lanes for v in api.lane.getLastStepVehicleIDs(lane)):
            if vid != EGO_ID and api.vehicle.getLanePosition(vid) < ENTRY_CLEAR_M:
                api.vehicle.remove(vid)
        log.debug("cleared the ego's entry stretch after %d s without a gap", ENTRY_CLEAR_AFTER_S)
