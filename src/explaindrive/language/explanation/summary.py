"""State records for LLM-2/LLM-3 and the human-readable environment summary.

A :class:`StateRecord` is the JSON shape the decision and explanation modules read::

    {"request": "fast", "action": -2,
     "state": {"v_ego": 8.0, "v_lim": 13.9, "d_lead": 22.0, "dv": 1.5,
               "d_tl": 35.0, "tl_state": "red", "d_cross": null, "d_yield": null},
     "history": {"slow_s": 6.0, "stopped_s": 0.0, "drop_mps": 2.0}}

``null`` means nothing within sensor range. ``d_yield`` (optional) is the distance to the
stop line of a junction where the car must give way now, to a foe with priority (a minor
road, a priority junction, a permissive turn); the env holds the car there with a virtual
leader, which the record does not show as a vehicle. ``history`` (optional) is what the passenger
has felt up to the step (:mod:`~explaindrive.language.explanation.history`); a ride fills
it, a record of a single step leaves it out. The summary and the decision ignore
objects farther than a cut-off (50 m in the paper), see :meth:`StateRecord.nearby`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Literal, TypeVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from explaindrive.commands import Command
from explaindrive.env.state import SENSOR_RANGE_M, DrivingState, LightState
from explaindrive.language.explanation.hazards import (
    Factor,
    Hazard,
    braking_hazards,
    headway_s,
    stopping_distance_m,
    ttc_s,
)
from explaindrive.language.explanation.history import DROP_WINDOW_S, SLOW_MARGIN_MPS, RideHistory
from explaindrive.validation import describe_errors

_M = TypeVar("_M", bound=BaseModel)

RequestLabel = Literal["fast", "comfort", "stop"]
LightLabel = Literal["green", "yellow", "red"]

SUMMARY_CUTOFF_M = 50.0  # [m] objects farther than this are left out of summaries and decisions
RESIDENTIAL_LIMIT_MPS = 30 / 3.6 + 0.05  # [m/s] limits up to 30 km/h are treated as residential
SEEN_VIRTUAL_LEADER_TOL_M = 2.0  # [m] in the noisy state seen: a leader this near a line is virtual

_ACTION_TEXT: dict[int, str] = {
    -3: "braking hard (-3 m/s)",
    -2: "braking (-2 m/s)",
    -1: "slowing down gently (-1 m/s)",
    0: "keeping its speed",
    1: "speeding up gently (+1 m/s)",
    2: "accelerating (+2 m/s)",
    3: "accelerating hard (+3 m/s)",
}


class RecordState(BaseModel):
    """Traffic context of one decision step; ``None`` = nothing in range."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    v_ego: float = Field(ge=0.0)  # [m/s]
    v_lim: float = Field(gt=0.0)  # [m/s]
    d_lead: float | None = Field(default=None, ge=0.0)  # [m]
    dv: float | None = None  # [m/s] ego minus leader, > 0 when closing
    d_tl: float | None = Field(default=None, ge=0.0)  # [m]
    tl_state: LightLabel | None = None
    d_cross: float | None = Field(default=None, ge=0.0)  # [m]
    d_yield: float | None = Field(default=None, ge=0.0)  # [m] a yield line in force

    @model_validator(mode="after")
    def _consistent(self) -> RecordState:
        if (self.d_tl is None) != (self.tl_state is None):
            raise ValueError("d_tl and tl_state must both be set or both be null")
        if self.d_lead is None and self.dv is not None:
            raise ValueError("dv given without a leader (d_lead is null)")
        return self

    def within(self, cutoff_m: float) -> RecordState:
        """The same state with every object farther than ``cutoff_m`` removed."""
        lead = self.d_lead is not None and self.d_lead <= cutoff_m
        light = self.d_tl is not None and self.d_tl <= cutoff_m
        cross = self.d_cross is not None and self.d_cross <= cutoff_m
        give_way = self.d_yield is not None and self.d_yield <= cutoff_m
        return RecordState(
            v_ego=self.v_ego,
            v_lim=self.v_lim,
            d_lead=self.d_lead if lead else None,
            dv=(self.dv if self.dv is not None else 0.0) if lead else None,
            d_tl=self.d_tl if light else None,
            tl_state=self.tl_state if light else None,
            d_cross=self.d_cross if cross else None,
            d_yield=self.d_yield if give_way else None,
        )


class StateRecord(BaseModel):
    """What LLM-2 and LLM-3 see: the confirmed request, the action and the state."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    request: RequestLabel
    action: int = Field(ge=-3, le=3)  # [m/s] speed change of this step
    state: RecordState
    history: RideHistory | None = None

    @property
    def command(self) -> Command:
        """The request as a :class:`Command`."""
        return Command.parse(self.request)

    def nearby(self, cutoff_m: float = SUMMARY_CUTOFF_M) -> RecordState:
        """The state restricted to objects within ``cutoff_m`` (paper: 50 m)."""
        return self.state.within(cutoff_m)

    @classmethod
    def from_observation(
        cls,
        obs: NDArray[np.floating],
        action_change_mps: int,
        *,
        yield_gap_m: float | None = None,
    ) -> StateRecord:
        """Build a record from the env's raw (not normalised) 8-dim observation.

        Distances at or beyond ``SENSOR_RANGE_M`` become ``None``. A leader that sits
        on a red/yellow stop line, at an occupied crossing or on the yield line is the
        env's virtual leader (paper, "virtual leader"), not a vehicle, and is dropped.

        Args:
            obs: observation in ``explaindrive.env.state.STATE_NAMES`` order.
            action_change_mps: the speed change chosen for this step, -3..3 [m/s].
            yield_gap_m: the gap to the yield line where the car must give way, perceived
                with ``obs`` (the env's ``info["yield_gap_m"]``); ``None`` or the sensor
                range: none.

        Raises:
            ValueError: on a wrong shape or an out-of-range value.
        """
        s = DrivingState.from_array(np.asarray(obs, dtype=np.float64))
        light = s.d_tl < SENSOR_RANGE_M
        cross = s.d_cross < SENSOR_RANGE_M
        colour = LightState(s.tls) if light else None
        d_yield = yield_gap_m if yield_gap_m is not None and yield_gap_m < SENSOR_RANGE_M else None
        stop_line = s.d_tl if colour in (LightState.RED, LightState.YELLOW) else None
        lines = [d for d in (stop_line, s.d_cross if cross else None, d_yield) if d is not None]
        lead = s.d_lead < SENSOR_RANGE_M and all(
            abs(s.d_lead - line) > SEEN_VIRTUAL_LEADER_TOL_M for line in lines
        )
        try:
            return cls(
                request=Command(s.cmd).label,  # type: ignore[arg-type]
                action=int(action_change_mps),
                state=RecordState(
                    v_ego=round(s.v_ego, 2),
                    v_lim=round(s.v_lim, 2),
                    d_lead=round(s.d_lead, 1) if lead else None,
                    dv=round(s.dv, 2) if lead else None,
                    d_tl=round(s.d_tl, 1) if light else None,
                    tl_state=colour.label if colour is not None else None,  # type: ignore[arg-type]
                    d_cross=round(s.d_cross, 1) if cross else None,
                    d_yield=round(d_yield, 1) if d_yield is not None else None,
                ),
            )
        except ValidationError as exc:
            raise ValueError(f"observation does not make a valid state record: {exc}") from exc

    @classmethod
    def from_json(cls, text: str, *, source: str = "<string>") -> StateRecord:
        """Parse a record from JSON text.

        Raises:
            ValueError: with ``source`` in the message when the JSON is malformed or invalid.
        """
        return _parse(cls, text, source)

    @classmethod
    def load(cls, path: str | Path) -> StateRecord:
        """Read a record from a JSON file.

        Raises:
            FileNotFoundError: if the file does not exist.
            ValueError: if its content is not a valid record.
        """
        p = Path(path)
        if not p.is_file():
            raise FileNotFoundError(f"state record file not found: {p}")
        return cls.from_json(p.read_text(encoding="utf-8"), source=str(p))


def _parse(model: type[_M], text: str, source: str) -> _M:
    try:
        raw = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{source}: not valid JSON ({exc.msg} at line {exc.lineno})") from exc
    try:
        return model.model_validate(raw)
    except ValidationError as exc:
        raise ValueError(f"{source}: invalid state record: {describe_errors(exc)}") from exc


def describe_action(change_mps: int) -> str:
    """Short text of an action for the prompts ("braking hard (-3 m/s)")."""
    if change_mps not in _ACTION_TEXT:
        raise ValueError(f"speed change {change_mps!r} is outside -3..3 m/s")
    return _ACTION_TEXT[change_mps]


def area_type(v_lim_mps: float) -> str:
    """``residential`` for limits up to 30 km/h, else ``urban``."""
    return "residential" if v_lim_mps <= RESIDENTIAL_LIMIT_MPS else "urban"


def _kmh(v_mps: float) -> int:
    return round(v_mps * 3.6)


def environment_summary(record: StateRecord, cutoff_m: float = SUMMARY_CUTOFF_M) -> str:
    """The paper's human-readable environment summary (section 4.2), most urgent first.

    Objects farther than ``cutoff_m`` are left out. The objects present are listed by
    urgency (:func:`~explaindrive.language.explanation.hazards.braking_hazards`: the one the car has
    to brake for first leads), and a last sentence names the most urgent reason to slow
    down, with the figure that makes it urgent. A light, a leader and a crossing that are
    absent are said to be; a junction where the car must give way is named only when it is.

    Example:
        ``Ego speed 8.0 m/s (29 km/h); speed limit 13.9 m/s (50 km/h); urban area.
        Red traffic light in 35 m. Vehicle ahead at 22 m, closing at 1.5 m/s.
        No pedestrian crossing within 50 m. Most urgent: the red traffic light 35 m
        ahead (a comfortable stop needs 16 m).``
    """
    s = record.nearby(cutoff_m)
    parts = [
        f"Ego speed {s.v_ego:.1f} m/s ({_kmh(s.v_ego)} km/h); speed limit {s.v_lim:.1f} m/s "
        f"({_kmh(s.v_lim)} km/h); {area_type(s.v_lim)} area."
    ]
    hazards = braking_hazards(s)
    urgent = [h.factor.value for h in hazards]
    present = {
        "lead_vehicle": _lead_sentence(s),
        "traffic_light": _light_sentence(s),
        "pedestrian": _crossing_sentence(s),
        "give_way": _yield_sentence(s),
    }
    order = sorted(present, key=lambda f: urgent.index(f) if f in urgent else len(urgent))
    parts += [present[f] for f in order if present[f] is not None]  # type: ignore[misc]
    limit = f"{cutoff_m:g} m"
    absent = {
        "lead_vehicle": f"No vehicle ahead within {limit}.",
        "traffic_light": f"No traffic light within {limit}.",
        "pedestrian": f"No pedestrian crossing within {limit}.",
    }
    parts += [absent[f] for f in order if present[f] is None and f in absent]
    if hazards:
        parts.append(f"Most urgent: {_urgency_phrase(s, hazards[0])}.")
    return " ".join(parts)


def history_summary(record: StateRecord) -> str:
    """What the passenger has felt up to the step, in words ("" without a history or with
    nothing to tell): how long the car has been slow or standing, the speed it just lost.

    Example:
        ``8 s at least 11 km/h under the limit; 4.0 m/s of speed lost in the last 3 s.``
    """
    h = record.history
    if h is None:
        return ""
    parts = []
    if h.stopped_s > 0:
        parts.append(f"standing for {h.stopped_s:.0f} s")
    elif h.slow_s > 0:
        parts.append(f"{h.slow_s:.0f} s at least {_kmh(SLOW_MARGIN_MPS)} km/h under the limit")
    if h.drop_mps > 0:
        parts.append(f"{h.drop_mps:.1f} m/s of speed lost in the last {DROP_WINDOW_S} s")
    return "; ".join(parts) + "." if parts else ""


def _lead_sentence(s: RecordState) -> str | None:
    if s.d_lead is None:
        return None
    dv = s.dv or 0.0
    if dv > 0.05:
        rel = f", closing at {dv:.1f} m/s"
    elif dv < -0.05:
        rel = f", pulling away at {-dv:.1f} m/s"
    else:
        rel = ", same speed"
    return f"Vehicle ahead at {s.d_lead:.0f} m{rel}."


def _light_sentence(s: RecordState) -> str | None:
    if s.d_tl is None or s.tl_state is None:
        return None
    return f"{s.tl_state.capitalize()} traffic light in {s.d_tl:.0f} m."


def _crossing_sentence(s: RecordState) -> str | None:
    if s.d_cross is None:
        return None
    return f"Pedestrian crossing the street {s.d_cross:.0f} m ahead."


def _yield_sentence(s: RecordState) -> str | None:
    if s.d_yield is None:
        return None
    return f"Junction in {s.d_yield:.0f} m where we must give way: a car with priority is coming."


def _urgency_phrase(s: RecordState, hazard: Hazard) -> str:
    """What makes ``hazard`` urgent, in words ("the red traffic light 15 m ahead (...)")."""
    need = f"a comfortable stop needs {stopping_distance_m(s.v_ego):.0f} m"
    if hazard.factor is Factor.TRAFFIC_LIGHT:
        return f"the {s.tl_state} traffic light {s.d_tl:.0f} m ahead ({need})"
    if hazard.factor is Factor.PEDESTRIAN:
        return f"the pedestrian crossing {s.d_cross:.0f} m ahead ({need})"
    if hazard.factor is Factor.GIVE_WAY:
        return f"giving way at the junction {s.d_yield:.0f} m ahead ({need})"
    if hazard.factor is Factor.LEAD_VEHICLE:
        ttc = ttc_s(s)
        timing = (
            f"time to collision {ttc:.1f} s"
            if math.isfinite(ttc)
            else f"time headway {headway_s(s):.1f} s"
        )
        return f"the vehicle {s.d_lead:.0f} m ahead ({timing})"
    return f"the {_kmh(s.v_lim)} km/h speed limit (ego speed {_kmh(s.v_ego)} km/h)"
