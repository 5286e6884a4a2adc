"""LLM-3 shared pieces: explanations, the template generator and the grounding check."""

from __future__ import annotations

import hashlib
import re
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any

from explaindrive.language.explanation.decision import (
    Factor,
    lasting_standstill,
    noticed_delay,
)
from explaindrive.language.explanation.history import SLOW_MARGIN_MPS
from explaindrive.language.explanation.summary import SUMMARY_CUTOFF_M, RecordState, StateRecord

# Giving way to a pedestrian is the crossing's, not a junction's.
_NOT_TO_PEDESTRIANS = (
    r"(?!\s+to\s+(the\s+|a\s+|an\s+)?"
    r"(pedestrians?|people|someone|somebody|person|child(ren)?|kids?|walkers?)\b)"
)
# Words that name each factor; used to check that a text is grounded in the state.
_FACTOR_PATTERNS: dict[Factor, re.Pattern[str]] = {
    Factor.TRAFFIC_LIGHT: re.compile(r"\b(traffic[- ]lights?|lights?|signals?)\b", re.I),
    Factor.PEDESTRIAN: re.compile(
        r"\b(pedestrians?|crosswalk|zebra|child(ren)?|kids?|walkers?|passers-by|passer-by)\b"
        r"|\b(someone|somebody|people|person|a man|a woman)\s+((is|are)\s+)?"
        r"(crossing|walking|on the (crossing|road|street))\b",
        re.I,
    ),
    Factor.LEAD_VEHICLE: re.compile(
        r"\b(vehicles?|cars?|trucks?|bus|van|leader)\s+(ahead|in front)|\b(vehicle|car) "
        r"(just )?ahead|\bleading (vehicle|car)|\bheadway\b|\bthe (car|vehicle) in front",
        re.I,
    ),
    Factor.GIVE_WAY: re.compile(
        rf"\bgiv(e|es|ing|en) way\b{_NOT_TO_PEDESTRIANS}|\byield(s|ing|ed)?\b{_NOT_TO_PEDESTRIANS}"
        r"|\bright[- ]of[- ]way\b|\bpriority (road|traffic)\b"
        r"|\b(cars?|vehicles?|traffic|road) (with|that has|which has|has|have) (the )?priority\b",
        re.I,
    ),
    Factor.SPEED_LIMIT: re.compile(r"\bspeed[- ]limits?\b|\blimit\b", re.I),
}


@dataclass(frozen=True, slots=True)
class Explanation:
    """Outcome of LLM-3.

    Attributes:
        text: one or two sentences for the passenger.
        factor: the factor the explanation is about.
        backend: backend that answered; ``fallback`` when ``embedded`` stood in.
        latency_s: wall time of the call [s].
        error: why the configured backend was bypassed, when ``fallback``.
        raw_reply: the remote model's reply as it came (for the ride log only; the
            passenger sees ``text``).
        vetoed: a remote reply came but failed the check against the state (``fallback``
            too: the template stood in).
    """

    text: str
    factor: Factor | None
    backend: str
    fallback: bool = False
    latency_s: float = 0.0
    error: str | None = None
    raw_reply: str | None = None
    vetoed: bool = False


class Explainer(ABC):
    """LLM-3: explains an action that goes against the passenger's request."""

    name: str = "abstract"

    @abstractmethod
    def explain(self, record: StateRecord, factor: Factor | None) -> Explanation:
        """Explain the record's action, naming ``factor`` (from the decision)."""


def mentioned_factors(text: str) -> set[Factor]:
    """Factors a text names (by the vocabulary of :data:`_FACTOR_PATTERNS`)."""
    return {f for f, pattern in _FACTOR_PATTERNS.items() if pattern.search(text)}


def present_factors(state: RecordState) -> set[Factor]:
    """Factors present in a (cut-off) state; the speed limit is always present."""
    found = {Factor.SPEED_LIMIT}
    if state.d_tl is not None:
        found.add(Factor.TRAFFIC_LIGHT)
    if state.d_cross is not None:
        found.add(Factor.PEDESTRIAN)
    if state.d_lead is not None:
        found.add(Factor.LEAD_VEHICLE)
    if state.d_yield is not None:
        found.add(Factor.GIVE_WAY)
    return found


def cause_present(state: RecordState, factor: Factor | None) -> bool:
    """Whether ``factor`` still gives a reason in a (cut-off) state: a red or yellow light,
    a pedestrian on the crossing, a vehicle ahead, a yield line in force, the limit
    (always); ``None`` (a neutral explanation): always."""
    if factor is Factor.TRAFFIC_LIGHT:
        return state.tl_state in ("red", "yellow")
    if factor is Factor.PEDESTRIAN:
        return state.d_cross is not None
    if factor is Factor.LEAD_VEHICLE:
        return state.d_lead is not None
    if factor is Factor.GIVE_WAY:
        return state.d_yield is not None
    return True


@dataclass(frozen=True, slots=True)
class Grounding:
    """Result of :func:`check_grounding`.

    Attributes:
        names_factor: the text names the expected factor (with none expected: a factor
            present in the state).
        absent: factors the text names that the state does not hold.
    """

    names_factor: bool
    absent: tuple[Factor, ...]

    @property
    def ok(self) -> bool:
        """The text names the expected factor and nothing absent from the state."""
        return self.names_factor and not self.absent


def check_grounding(
    text: str, factor: Factor | None, record: StateRecord, cutoff_m: float = SUMMARY_CUTOFF_M
) -> Grounding:
    """Check that ``text`` names ``factor`` (with ``None``: some factor present in the
    state) and no factor absent from the state."""
    said = mentioned_factors(text)
    present = present_factors(record.nearby(cutoff_m))
    absent = tuple(sorted(said - present))
    names = bool(said & present) if factor is None else factor in said
    return Grounding(names_factor=names, absent=absent)


# --- the embedded generator ----------------------------------------------------------------

# What the car is doing, in words true of the action and the speed: "stop" only when
# this step ends at a standstill, "easing off" only for gentle braking (-1 m/s).
_OPENERS: dict[str, tuple[str, ...]] = {
    "stopping": (
        "I'm bringing us to a stop",
        "I'm stopping the car",
        "I'm bringing the car to a halt",
    ),
    "hard_brake": ("I'm braking hard", "I had to brake hard", "I'm braking sharply"),
    "firm_brake": ("I'm braking", "I'm slowing us down firmly", "I had to brake firmly"),
    "gentle_brake": (
        "I'm easing off a little",
        "I'm slowing down gently",
        "I'm reducing our speed a little",
    ),
    "hold": (
        "I'm holding our speed for now",
        "I'm not speeding up just yet",
        "I'm keeping us steady for a moment",
    ),
    "wait": (
        "We're waiting here for a moment",
        "I'm keeping us stopped for now",
        "We're staying put for a moment",
    ),
    "accelerate": (
        "Sorry for the quick acceleration",
        "Apologies for the sudden burst of speed",
        "Sorry for speeding up so briskly",
    ),
}
SEEN_STANDSTILL_MPS = 0.5  # [m/s] in the state seen, the car counts as stopped at or below this
_REASONS: dict[Factor, tuple[str, ...]] = {
    Factor.PEDESTRIAN: (
        "because a pedestrian is crossing the street {d_cross} m ahead",
        "to let a pedestrian cross safely {d_cross} m ahead of us",
        "since someone is on the pedestrian crossing {d_cross} m ahead",
    ),
    Factor.TRAFFIC_LIGHT: (
        "because the traffic light {d_tl} m ahead is {tl_state}",
        "since the light {d_tl} m ahead of us is {tl_state}",
        "as the traffic light coming up in {d_tl} m is {tl_state}",
    ),
    Factor.LEAD_VEHICLE: (
        "to keep a safe distance from the vehicle ahead, {d_lead} m away",
        "because the car ahead is only {d_lead} m away",
        "to leave enough room to the vehicle in front, which is {d_lead} m ahead",
    ),
    Factor.GIVE_WAY: (
        "to give way at the junction {d_yield} m ahead: a car with priority is coming",
        "because we must give way at the junction {d_yield} m ahead to a car with priority",
        "as a car with priority is coming at the junction {d_yield} m ahead",
    ),
    Factor.SPEED_LIMIT: (
        "to stay within the {v_lim_kmh} km/h speed limit here",
        "because the speed limit on this stretch is {v_lim_kmh} km/h",
        "so that we respect the {v_lim_kmh} km/h speed limit",
    ),
}

_ACCEL_REASON = (
    "the traffic light {d_tl} m ahead just turned yellow, too close to pull up "
    "comfortably, so it is safer to clear the intersection"
)

_CLOSERS: dict[Factor, tuple[str, ...]] = {
    Factor.PEDESTRIAN: (
        "We'll continue as soon as the way is clear.",
        "Their safety comes first, and we'll be moving again shortly.",
        "It only takes a moment, thanks for your patience.",
    ),
    Factor.TRAFFIC_LIGHT: (
        "We'll be on our way again as soon as it turns green.",
        "We'll pick up speed again right after it changes.",
        "It won't be long, thanks for your patience.",
    ),
    Factor.LEAD_VEHICLE: (
        "We'll speed up again once there's more room.",
        "Keeping this gap keeps the ride safe for everyone.",
        "I'll pick up the pace as soon as it is safe.",
    ),
    Factor.GIVE_WAY: (
        "We'll go as soon as it has passed.",
        "It has the right of way, so we let it pass first.",
        "We'll be on our way once the junction is clear.",
    ),
    Factor.SPEED_LIMIT: (
        "We'll still get you there safely and on time.",
        "Driving faster here would not be safe or legal.",
        "Thanks for understanding, we're making good progress.",
    ),
}


def _phrasing_key(record: StateRecord) -> str:
    """What picks a record's phrasing: its step, not its history (a record without a yield
    line is keyed as before ``d_yield`` existed, so its phrasing stays the same)."""
    exclude: dict[str, Any] = {"history": True}
    if record.state.d_yield is None:
        exclude["state"] = {"d_yield"}
    return record.model_dump_json(exclude=exclude)


def _pick(options: tuple[str, ...], key: str) -> str:
    digest = hashlib.blake2b(key.encode(), digest_size=4).digest()
    return options[int.from_bytes(digest, "big") % len(options)]


def opener_kind(record: StateRecord) -> str:
    """How the record's motion reads in words: ``wait`` (standing, not moving off),
    ``accelerate``, ``stopping`` (this step ends at a standstill), ``hard_brake`` (-3),
    ``firm_brake`` (-2), ``gentle_brake`` (-1, "easing off") or ``hold``.

    A car that stands still is never said to brake or ease off, whatever the action.
    """
    v = record.state.v_ego
    a = record.action
    if v <= SEEN_STANDSTILL_MPS and a <= 0:
        return "wait"
    if a > 0:
        return "accelerate"
    if a < 0 and v + a <= SEEN_STANDSTILL_MPS:
        return "stopping"
    if a < 0:
        return {-3: "hard_brake", -2: "firm_brake"}.get(a, "gentle_brake")
    return "hold"


def _following(record: StateRecord, s: RecordState) -> str | None:
    """What a passenger notices behind a slower or stopped car, in words, when the ride's
    history shows it (a lasting delay, a felt drop, a lasting standstill); else ``None``."""
    if s.d_lead is None or not (noticed_delay(record) or lasting_standstill(record)):
        return None
    v_lead = max(s.v_ego - (s.dv or 0.0), 0.0)
    if opener_kind(record) == "wait" and v_lead <= SEEN_STANDSTILL_MPS:
        return (
            f"We're waiting behind the stopped car ahead, {s.d_lead:.0f} m away. "
            "We'll move on as soon as it does."
        )
    car = "the slower car ahead" if v_lead <= s.v_lim - SLOW_MARGIN_MPS else "the car ahead"
    doing = (
        f"We're holding {round(s.v_ego * 3.6)} km/h behind"
        if record.action == 0
        else "I'm easing off behind"
    )
    return (
        f"{doing} {car}, {s.d_lead:.0f} m away, which is doing {round(v_lead * 3.6)} km/h. "
        "I'll speed up when it clears."
    )


def neutral_explanation(record: StateRecord) -> str:
    """A sentence true of the motion that names no factor, for a state with nothing to name."""
    kind = opener_kind(record)
    opener = _pick(_OPENERS[kind], _phrasing_key(record) + "o")
    if kind == "accelerate":
        return f"{opener}, it was the safer choice here."
    return f"{opener}, it is the safe choice here."


def template_explanation(
    record: StateRecord, factor: Factor, cutoff_m: float = SUMMARY_CUTOFF_M
) -> str:
    """One or two friendly sentences naming ``factor`` with its distance (deterministic).

    The wording varies with the record (a hash picks among several phrasings) but
    only the chosen factor and values from the state are ever mentioned, and what the
    car is said to do matches the action and the speed (:func:`opener_kind`).

    Raises:
        ValueError: if ``factor`` is not present in the record's state within ``cutoff_m``,
            or for an acceleration that only a yellow light too close to stop at explains.
    """
    s = record.nearby(cutoff_m)
    if factor not in present_factors(s):
        raise ValueError(f"factor {factor.value} is not in the state within {cutoff_m:g} m")
    values = {
        "d_cross": f"{s.d_cross:.0f}" if s.d_cross is not None else "",
        "d_tl": f"{s.d_tl:.0f}" if s.d_tl is not None else "",
        "tl_state": s.tl_state or "",
        "d_lead": f"{s.d_lead:.0f}" if s.d_lead is not None else "",
        "d_yield": f"{s.d_yield:.0f}" if s.d_yield is not None else "",
        "v_lim_kmh": f"{round(s.v_lim * 3.6)}",
    }
    key = _phrasing_key(record)
    kind = opener_kind(record)
    opener = _pick(_OPENERS[kind], key + "o")
    if kind == "accelerate":  # only a yellow light too close to stop at explains it
        if record.action < 2 or factor is not Factor.TRAFFIC_LIGHT or s.tl_state != "yellow":
            raise ValueError(
                f"accelerating by {record.action} m/s cannot be explained by {factor.value}"
            )
        return f"{opener}: {_ACCEL_REASON.format(**values)}. Everything is under control."
    if factor is Factor.LEAD_VEHICLE and (following := _following(record, s)) is not None:
        return following
    reason = _pick(_REASONS[factor], key + "r").format(**values)
    closer = _pick(_CLOSERS[factor], key + "c")
    if record.request == "comfort" and record.action <= -2:
        opener = f"Sorry, {opener}"  # harsh braking under comfort: "Sorry, I'm braking hard"
    return f"{opener} {reason}. {closer}"
