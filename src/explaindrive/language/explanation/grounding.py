"""Is an explanation true of the state? Checks of what a text claims against a record.

:func:`wording_problems` compares what the text says the car is doing (stopping,
braking hard or gently, holding, waiting, accelerating) with the action and the speed.
:func:`reply_problems` adds the checks a remote model's reply must pass before it reaches
the passenger: it is an explanation (not a refusal, and it names the factor it explains),
names no factor and no kind of hazard the state does not hold (a junction needs a light or
a yield line in the state), gives the light's colour as it is, and gives distances and
speeds within a tolerance of the state's.
"""

from __future__ import annotations

import re

from explaindrive.language.explanation.explainer import SEEN_STANDSTILL_MPS, check_grounding
from explaindrive.language.explanation.hazards import Factor
from explaindrive.language.explanation.summary import SUMMARY_CUTOFF_M, RecordState, StateRecord

MAX_EXPLANATION_CHARS = 400
DISTANCE_TOLERANCE_M = 3.0  # [m] a distance in a text may differ this much from the state's
DISTANCE_TOLERANCE = 0.2  # ... or this share of it, whichever is larger
SPEED_TOLERANCE_KMH = 5.0  # [km/h] a speed in a text may differ this much from the state's

_I = re.IGNORECASE
# Claims that the car has stopped or is stopping sharply: true only at a standstill.
_STOPPED = re.compile(
    r"\b(quick|sudden|abrupt|sharp|hard|emergency)\s+stop\b|\bstopped\b|\bstandstill\b"
    r"|\bhalted\b|\b(came|come|coming|bring(ing)?|brought)\s+(us\s+|the car\s+)?to a (stop|halt)",
    _I,
)
# Any other stop: true at a standstill, or while braking for a stop line ahead.
_STOP = re.compile(r"\bstop(ping|s)?\b(?!\s+line)|\bhalt(ing)?\b", _I)
_GENTLE = re.compile(
    r"\beas(e|es|ing) off\b|\bgentle brak|\blight(ly)? brak"
    r"|\b(slow(ing)?( down)?|brak(e|ing)|reduc(e|ing)( our| the)? speed)\s+"
    r"(gently|softly|slightly|a little|a bit|a touch)\b",
    _I,
)
_HARD = re.compile(
    r"\b(brak(e|ed|ing)|slow(ed|ing)? (us )?down)\s+(hard|sharply|firmly|suddenly|abruptly)\b"
    r"|\b(hard|sharp|firm|sudden|abrupt|heavy|emergency)\s+brak",
    _I,
)
_ACCELERATING = re.compile(
    r"\b(i'm|i am|we're|we are)\s+(speeding up|accelerating|picking up speed)\b"
    r"|\b(quick|sudden|hard|brisk)\s+acceleration\b|\bburst of speed\b",
    _I,
)
_SLOWING = re.compile(
    r"\b(i'm|i am|we're|we are|i've|i have|i had to|had to)\s+"
    r"(slow(ing|ed)?|brak(e|ing|ed)|reduc(e|ing|ed))",
    _I,
)
_HOLDING = re.compile(r"\bholding (our|the|this) speed\b|\bkeeping us steady\b", _I)
_WAITING = re.compile(r"\bwaiting\b|\bstaying put\b|\bkeeping us stopped\b", _I)

_REFUSAL = re.compile(
    r"\b(i'm|i am) (sorry, but|unable|not able)\b|\bi (can't|cannot|can not|won't) "
    r"(help|assist|provide|do|comply|answer)\b|\bas an ai\b|\blanguage model\b",
    _I,
)
# Hazards a state record cannot hold: naming one is invented.
_UNSUPPORTED = re.compile(
    r"\b(cyclists?|bicycles?|bikes?|motorcycles?|scooters?|school zones?|schools?"
    r"|construction|road ?works|work zones?|animals?|dogs?|cats?|deer|ambulances?"
    r"|fire (engine|truck)s?|police|sirens?|rain|raining|wet|ice|icy|fog|foggy|snow"
    r"|accidents?|crash(es)?|collisions?|potholes?|obstacles?|debris|swerv\w*|roadblocks?"
    r"|(speed )?cameras?|radars?|speed traps?|traffic (conditions|jams?)|heavy traffic"
    r"|congestion|rush hour|sharp (bend|curve|turn)s?|bends?|curves?|hills?)\b",
    _I,
)
# A junction is in the state only as a light's or a yield line's.
_JUNCTION = re.compile(r"\b(junctions?|intersections?|crossroads)\b", _I)
_COLOURS = {"red": "red", "yellow": "yellow", "amber": "yellow", "green": "green"}
_COLOUR_CLAIMS = (
    re.compile(r"\b(?P<colour>red|yellow|amber|green)\s+(traffic\s+)?(light|signal)s?\b", _I),
    re.compile(
        r"\b(light|signal)s?\b[^.!?]{0,40}?\b(is|was|turned|has turned|just turned|shows|"
        r"showing|'s)\s+(now\s+)?(?P<colour>red|yellow|amber|green)\b",
        _I,
    ),
)
_DISTANCE = re.compile(r"(\d+(?:\.\d+)?)\s*(m|metres|meters|metre|meter)\b", _I)
_SPEED_KMH = re.compile(r"(\d+(?:\.\d+)?)\s*(km/h|kmh|kph)\b", _I)


def wording_problems(text: str, record: StateRecord) -> list[str]:
    """What ``text`` says the car does that its action and speed do not bear out."""
    v = record.state.v_ego
    a = record.action
    moving = v > SEEN_STANDSTILL_MPS
    at_rest_after = v + a <= SEEN_STANDSTILL_MPS
    stop_ahead = a < 0 and _has_stop_target(record.state)
    rules = (
        (_STOPPED, at_rest_after, "a stop"),
        (_STOP, at_rest_after or stop_ahead, "stopping"),
        (_GENTLE, a == -1 and moving, "gentle braking"),
        (_HARD, a <= -2 and moving, "hard braking"),
        (_ACCELERATING, a > 0, "accelerating"),
        (_SLOWING, a < 0 and moving, "slowing down"),
        (_HOLDING, a == 0 and v > SEEN_STANDSTILL_MPS, "holding speed"),
        (_WAITING, a <= 0 and v <= SEEN_STANDSTILL_MPS, "waiting"),
    )
    rest = _STOPPED.sub(" ", text)  # a claimed stop is one problem, not two
    return [
        f"says {claim} while the action is {a:+d} m/s at {v:.1f} m/s"
        for pattern, true, claim in rules
        if not true and pattern.search(rest if pattern is _STOP else text)
    ]


def _has_stop_target(s: RecordState) -> bool:
    return (
        s.d_cross is not None
        or s.d_yield is not None
        or (s.d_tl is not None and s.tl_state in ("red", "yellow"))
    )


def reply_problems(
    text: str, record: StateRecord, factor: Factor | None, cutoff_m: float = SUMMARY_CUTOFF_M
) -> list[str]:
    """Why a remote model's explanation may not be shown (empty when it may).

    Args:
        text: the reply.
        record: the state it explains.
        factor: the factor the decision chose; the reply must name it.
        cutoff_m: objects farther away are not in the state.
    """
    text = text.strip()
    if not text or len(text) > MAX_EXPLANATION_CHARS:
        return [f"empty or too long ({len(text)} chars)"]
    if _REFUSAL.search(text):
        return ["a refusal, not an explanation"]
    s = record.nearby(cutoff_m)
    problems: list[str] = []
    grounding = check_grounding(text, factor, record, cutoff_m)
    if not grounding.names_factor and factor is not None:
        problems.append(f"does not name the {factor.value.replace('_', ' ')}")
    elif not grounding.names_factor:
        problems.append("names no factor of the state")
    if grounding.absent:
        problems.append(f"names factors not in the state: {', '.join(grounding.absent)}")
    invented = sorted({m.group(0).lower() for m in _UNSUPPORTED.finditer(text)})
    if s.d_tl is None and s.d_yield is None:
        invented += sorted({m.group(0).lower() for m in _JUNCTION.finditer(text)})
    if invented:
        problems.append(f"names hazards the state does not hold: {', '.join(invented)}")
    problems += _colour_problems(text, s)
    problems += _distance_problems(text, s)
    problems += _speed_problems(text, s)
    problems += wording_problems(text, record)
    return problems


def _colour_problems(text: str, s: RecordState) -> list[str]:
    said = {_COLOURS[m["colour"].lower()] for p in _COLOUR_CLAIMS for m in p.finditer(text)}
    if not said:
        return []
    if s.tl_state is None:
        return [f"gives a light colour ({', '.join(sorted(said))}) with no light in the state"]
    wrong = sorted(said - {s.tl_state})
    return [f"says the light is {', '.join(wrong)}; it is {s.tl_state}"] if wrong else []


def _distance_problems(text: str, s: RecordState) -> list[str]:
    known = [d for d in (s.d_lead, s.d_tl, s.d_cross, s.d_yield) if d is not None]
    out = []
    for m in _DISTANCE.finditer(text):
        said = float(m.group(1))
        if not any(
            abs(said - d) <= max(DISTANCE_TOLERANCE_M, DISTANCE_TOLERANCE * d) for d in known
        ):
            have = ", ".join(f"{d:.0f} m" for d in known) or "none"
            out.append(f"gives a distance of {said:g} m; the state has {have}")
    return out


def _close(said_m: float, actual_m: float) -> bool:
    return abs(said_m - actual_m) <= max(DISTANCE_TOLERANCE_M, DISTANCE_TOLERANCE * actual_m)


def _speed_problems(text: str, s: RecordState) -> list[str]:
    """Speeds said that are none of the car's, the limit's or the leader's."""
    known = [s.v_ego * 3.6, s.v_lim * 3.6]
    if s.d_lead is not None:
        known.append(max(s.v_ego - (s.dv or 0.0), 0.0) * 3.6)
    have = ", ".join(f"{k:.0f}" for k in known)
    return [
        f"gives a speed of {m.group(1)} km/h; the state has {have}"
        for m in _SPEED_KMH.finditer(text)
        if all(abs(float(m.group(1)) - k) > SPEED_TOLERANCE_KMH for k in known)
    ]
