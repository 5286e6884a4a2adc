"""Parameters of the urban scenario family: the one place that fixes their defaults and ranges.

The defaults are the paper's road (:mod:`explaindrive.sim.scenario.layout` builds it from
``ScenarioParams()``). Every field has a range; :mod:`explaindrive.sim.scenario.generator`
draws scenarios uniformly within the ranges written here. Keys are given dotted on the
command line (``--set j1.cycle_s=90``) and nested in ``scenario.yaml``.

The road, west to east (block lengths in metres)::

    W0 --approach_m-- J1 --j1_to_zone_m-- Z1 --zone_to_crossing_m-- PX
       --crossing_to_zone_end_m-- Z2 --zone_end_to_j2_m-- J2 --exit_m-- E0

``Z1``..``Z2`` is the low-limit zone around the zebra ``PX``. With ``priority_junction``,
``Z1`` is also an unsignalised priority junction where a side road with right of way
crosses the main road: the ego must yield there. With ``turn_lane_m``, the main road widens
to two eastbound lanes at ``T2``, that far before ``J2``; with ``joined_junction_m``, a
second signalised junction ``K1`` that far after ``J1`` runs on ``J1``'s programme; with
``left_turn``, the ego leaves ``J2`` along its north arm instead of driving on to ``E0``.
"""

from __future__ import annotations

from typing import Annotated, Any, Self

from pydantic import Field, model_validator

from explaindrive.config import ConfigModel, StrictModel

MIN_LIMIT_KMH = 20.0  # [km/h]
MAX_LIMIT_KMH = 70.0  # [km/h] below the observation's speed bound (20 m/s = 72 km/h)
LimitKmh = Annotated[float, Field(ge=MIN_LIMIT_KMH, le=MAX_LIMIT_KMH)]
Block = Annotated[float, Field(ge=60.0, le=600.0)]
"""A block length [m]: long enough to stop from 70 km/h (about 60 m at 3 m/s^2) before
the next junction."""
PedRate = Annotated[float, Field(ge=0.0, le=400.0)]
"""Pedestrians per hour in one direction (0: none)."""
TurnLaneM = Annotated[float, Field(ge=40.0, le=150.0)]
"""Length [m] of J2's left-turn lane, beside the straight lane up to the stop line."""
JoinedGapM = Annotated[float, Field(ge=20.0, le=60.0)]
"""From J1 to the junction K1 that shares its programme [m]."""
MIN_TAPER_GAP_M = 20.0  # [m] from Z2 to the start T2 of the turn lane, from K1 to Z1

YELLOW_BRAKE_MPS = 3.0  # [m/s per step] the braking a yellow must leave time for
YELLOW_STOP_MARGIN_M = 2.0  # [m] short of the line a car braking that hard stands
MAX_YELLOW_S = 5


def _hardest_stop_m(speed_mps: float) -> float:
    """[m] a car at ``speed_mps`` covers braking by :data:`YELLOW_BRAKE_MPS` per 1 s step from
    now, plus :data:`YELLOW_STOP_MARGIN_M`."""
    covered, v = YELLOW_STOP_MARGIN_M, speed_mps - YELLOW_BRAKE_MPS
    while v > 0.0:
        covered, v = covered + v, v - YELLOW_BRAKE_MPS
    return covered


def min_yellow_s(limit_kmh: float) -> int:
    """The shortest yellow [s] that leaves no dilemma zone before a light approached at up
    to ``limit_kmh``: at any speed up to the limit (whole m/s and the limit itself), a car
    that sees the yellow can either stand before the line braking by 3 m/s per step, or
    cross it keeping its speed before the red (in yellow minus one steps). 3 s up to
    50 km/h, 4 s at 60 and 70 km/h. A 3 s yellow at 60 km/h leaves a car at 16 m/s, 33-36 m
    out, no legal way but to speed up."""
    top = limit_kmh / 3.6
    speeds = [*range(1, int(top) + 1), top]
    for yellow in range(3, MAX_YELLOW_S + 1):
        if all(_hardest_stop_m(v) <= (yellow - 1) * v for v in speeds):
            return yellow
    return MAX_YELLOW_S


SIGNAL_FIXED_S = {"J1": 0, "J2": 3}
"""[s] phases a light has besides greens, yellows and all-reds: J2 keeps its side road green
3 s after its pedestrians' green ends (the crossing clears)."""
MIN_SIDE_GREEN_S = 5  # [s]


class SignalParams(StrictModel):
    """A static two-stream signal program: main road, then side road (and pedestrians)."""

    cycle_s: int = Field(ge=40, le=120)
    """Cycle length [s]."""
    main_green_s: int = Field(ge=10, le=100)
    """Green of the main road [s] (the split); the side road gets the rest of the cycle."""
    yellow_s: int = Field(default=3, ge=3, le=MAX_YELLOW_S)
    """Yellow after each green [s]; at least :func:`min_yellow_s` of the road's limit."""
    all_red_s: int = Field(default=2, ge=1, le=3)
    """All-red clearance after each yellow [s]."""
    offset_s: int = Field(default=0, ge=0, le=119)
    """Start of the program within the cycle [s] (a green wave between the lights)."""

    def side_green_s(self, fixed_s: int) -> int:
        """Green of the side road [s] given the light's other fixed phases."""
        return self.cycle_s - self.main_green_s - 2 * (self.yellow_s + self.all_red_s) - fixed_s

    def durations(self, fixed_s: int) -> tuple[int, ...]:
        """Phase durations in netconvert's order: main green, yellow, all red, side green,
        (side-only ``fixed_s``,) yellow, all red."""
        side = self.side_green_s(fixed_s)
        extra = (fixed_s,) if fixed_s else ()
        y, r = self.yellow_s, self.all_red_s
        return (self.main_green_s, y, r, side, *extra, y, r)


class DemandParams(StrictModel):
    """Vehicle flows at traffic level 1.0 [veh/h]; they scale with the level."""

    main_east: float = Field(default=900.0, ge=300.0, le=1200.0)
    """Eastbound on the main road, the ego's direction."""
    main_west: float = Field(default=450.0, ge=0.0, le=900.0)
    """Westbound on the main road."""
    j1_cross: float = Field(default=150.0, ge=0.0, le=300.0)
    """Across the main road at J1, each direction."""
    j2_turn_south: float = Field(default=180.0, ge=0.0, le=300.0)
    """From J2's south arm turning east ahead of the ego."""
    j2_turn_north: float = Field(default=120.0, ge=0.0, le=300.0)
    """From J2's north arm turning east ahead of the ego."""
    j2_cross: float = Field(default=60.0, ge=0.0, le=200.0)
    """Across the main road at J2, each direction."""
    z1_cross: float = Field(default=120.0, ge=0.0, le=300.0)
    """Across the main road at Z1, each direction, when Z1 is a priority junction
    (``ScenarioParams.priority_junction``; no flow without it)."""
    j2_left: float = Field(default=60.0, ge=0.0, le=300.0)
    """Eastbound on the main road turning left (north) at J2 from its left-turn lane, when
    J2 has one (``ScenarioParams.turn_lane_m``; no flow without it)."""


class ScenarioParams(ConfigModel):
    """A scenario of the family; the defaults are the paper's road."""

    config_name = "scenario"

    approach_m: Block = 400.0
    """From the start W0 to the first light J1 [m]."""
    j1_to_zone_m: Block = 200.0
    """From J1 to the start Z1 of the low-limit zone [m]."""
    zone_to_crossing_m: Block = 200.0
    """From Z1 to the zebra crossing PX [m]."""
    crossing_to_zone_end_m: Block = 200.0
    """From PX to the end Z2 of the zone [m]."""
    zone_end_to_j2_m: Block = 200.0
    """From Z2 to the second light J2 [m]."""
    exit_m: Block = 350.0
    """From J2 to the end E0 [m]."""
    limit_kmh: LimitKmh = 50.0
    """Speed limit of the main road outside the zone [km/h]."""
    zone_limit_kmh: LimitKmh = 30.0
    """Speed limit in the zone around the zebra [km/h]."""
    side_limit_kmh: LimitKmh = 50.0
    """Speed limit of the side roads [km/h]."""
    j1: SignalParams = SignalParams(cycle_s=60, main_green_s=37)
    """Signal program of J1."""
    j2: SignalParams = SignalParams(cycle_s=60, main_green_s=34, offset_s=25)
    """Signal program of J2 (its offset is against J1)."""
    zebra_peds_per_hour: PedRate = 90.0
    """Pedestrians crossing at the zebra PX per hour, each direction."""
    j2_peds_per_hour: PedRate = 120.0
    """Pedestrians crossing J2's west arm per hour, each direction."""
    demand: DemandParams = DemandParams()
    """Vehicle flows at traffic level 1.0."""
    priority_junction: bool = False
    """Z1 is an unsignalised priority junction: a side road crosses the main road there
    with right of way over it, so the ego's link is a minor one (SUMO's state ``m``) and
    it must yield to the side road's traffic. The paper's road has none."""
    turn_lane_m: TurnLaneM | None = None
    """J2's eastbound approach has two lanes for its last ``turn_lane_m`` metres (from the
    node T2): the left one turns left only, the right one goes straight or right (their
    arrows are explicit connections); the single lane before T2 leads into both. At most
    ``zone_end_to_j2_m`` minus 20 m. ``None``: one lane up to J2 (the paper's road)."""
    left_turn: bool = False
    """The ego's route turns left at J2 onto its north arm (``J2_J2N``) across the
    westbound traffic, which has the same green: its link is a permissive green (SUMO's
    state ``g``) and it must yield to the oncoming cars. ``False``: straight on to E0."""
    joined_junction_m: JoinedGapM | None = None
    """A second signalised junction K1, with a side road crossing the main road, this far
    after J1 [m]; one programme (J1's) runs both, so the ego passes two stop lines of one
    light. At most ``j1_to_zone_m`` minus 20 m. ``None``: no K1 (the paper's road)."""

    @model_validator(mode="after")
    def _check_junction_gaps(self) -> Self:
        checks = ((self.turn_lane_m, self.zone_end_to_j2_m, "turn_lane_m", "zone_end_to_j2_m"),
                  (self.joined_junction_m, self.j1_to_zone_m, "joined_junction_m",
                   "j1_to_zone_m"))  # fmt: skip
        for value, block, name, block_name in checks:
            if value is not None and value > block - MIN_TAPER_GAP_M:
                raise ValueError(
                    f"{name} {value:g} m leaves under {MIN_TAPER_GAP_M:g} m of its block "
                    f"{block_name} ({block:g} m)"
                )
        return self

    @model_validator(mode="after")
    def _check_signals(self) -> Self:
        for name in ("j1", "j2"):
            signal: SignalParams = getattr(self, name)
            side = signal.side_green_s(SIGNAL_FIXED_S[name.upper()])
            if side < MIN_SIDE_GREEN_S:
                raise ValueError(
                    f"{name}: the side road's green would be {side} s (cycle_s minus "
                    f"main_green_s and the yellow/all-red/clearance phases); at least "
                    f"{MIN_SIDE_GREEN_S} s is needed"
                )
            shortest = min_yellow_s(self.limit_kmh)
            if signal.yellow_s < shortest:
                raise ValueError(
                    f"{name}: yellow_s {signal.yellow_s} s is too short for a "
                    f"{self.limit_kmh:g} km/h road; at least {shortest} s, or a car that sees "
                    "the yellow can neither stop nor cross before red"
                )
            if signal.offset_s >= signal.cycle_s:
                raise ValueError(f"{name}: offset_s must be below cycle_s ({signal.cycle_s})")
        return self

    @classmethod
    def from_settings(cls, settings: list[str], base: ScenarioParams | None = None) -> Self:
        """Parameters from ``key=value`` texts with dotted keys (``j1.cycle_s=90``) over
        ``base`` (default: the paper's road).

        Raises:
            ConfigError: on a malformed setting, an unknown key or a value out of range.
        """
        from explaindrive.config import ConfigError, read_yaml

        data: dict[str, Any] = (base or cls()).to_dict()
        for item in settings:
            key, sep, text = item.partition("=")
            if not sep or not key.strip():
                raise ConfigError(f"scenario setting {item!r} must look like KEY=VALUE")
            *parents, leaf = key.strip().split(".")
            node = data
            for part in parents:
                child = node.get(part)
                if not isinstance(child, dict):
                    raise ConfigError(f"unknown scenario key {key.strip()!r}")
                node = child
            node[leaf] = read_yaml(text)
        return cls.from_dict(data)
