"""What a ride keeps: one record per step, the ride's counters, the passenger's requests."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from explaindrive.commands import Command
from explaindrive.ride.inputs import PassengerInput


@dataclass
class PassengerRequest:
    """A passenger line on its way to becoming a command."""

    id: int
    t: float  # [s] ride time
    line: PassengerInput
    confirm: bool | None
    """The scripted answer to the confirmation question (yes: ``True``); ``None`` leaves it to
    the ride's settings or the passenger."""
    intent: Command | None = None
    question: str | None = None


@dataclass
class StepRecord:
    """Everything that happened in one step (one line of ``events.jsonl``)."""

    t: float
    state: dict[str, float]
    command: str
    agent: str
    action: int
    speed_mps: float
    limit_mps: float
    reward: float
    flags: dict[str, bool]
    passenger: list[dict[str, Any]] = field(default_factory=list)
    decision: dict[str, Any] | None = None
    explanation: dict[str, Any] | None = None
    latency_s: dict[str, float] = field(default_factory=dict)
    shield: dict[str, Any] | None = None
    """When the safety shield replaced the network's choice: what the network chose [m/s]."""

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            "t": self.t,
            "state": self.state,
            "command": self.command,
            "agent": self.agent,
            "action": self.action,
            "speed_mps": self.speed_mps,
            "limit_mps": self.limit_mps,
            "reward": self.reward,
            "flags": self.flags,
            "passenger": self.passenger,
            "decision": self.decision,
            "explanation": self.explanation,
            "latency_s": self.latency_s,
            "shield": self.shield,
        }


MODULES = ("interpret", "decide", "explain")
"""The ride's language modules as counted: LLM-1, LLM-2, LLM-3."""


@dataclass
class ModuleCounts:
    """What became of one language module's answers in a ride.

    Attributes:
        used: the configured backend's own answer was used.
        fallback: the backend failed (an error, a timeout, an unreadable reply) and the
            embedded module answered instead.
        vetoed: the backend's reply was overruled by the embedded module or by the check
            against the state.
        late: the task passed the ride's deadline; its answer, if any, was dropped.
        stale: (explanations) it arrived after its cause had gone and was not shown.
    """

    used: int = 0
    fallback: int = 0
    vetoed: int = 0
    late: int = 0
    stale: int = 0

    def add(self, fallback: bool, vetoed: bool) -> None:
        """Count one answer."""
        if vetoed:
            self.vetoed += 1
        elif fallback:
            self.fallback += 1
        else:
            self.used += 1


@dataclass
class RideCounts:
    """Counters for the ride summary (``models``: per language module)."""

    lines: int = 0
    answers: int = 0
    questions: int = 0
    understood: int = 0
    asked_stop: int = 0
    """Lines the car asked about ("You want me to stop...?") without having read a STOP."""
    rephrase: int = 0
    confirmations: int = 0
    cancellations: int = 0
    explain_decisions: int = 0
    explanations: int = 0
    suppressed_explanations: int = 0
    fallbacks: int = 0
    late: int = 0
    errors: int = 0
    superseded: int = 0
    skipped_decisions: int = 0
    models: dict[str, ModuleCounts] = field(
        default_factory=lambda: {m: ModuleCounts() for m in MODULES}
    )

    @property
    def requests(self) -> int:
        """The passenger's lines that were neither an answer to a question nor a "why?"."""
        return self.lines - self.answers - self.questions

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dict (with ``requests``)."""
        out: dict[str, Any] = {k: v for k, v in self.__dict__.items() if k != "models"}
        out["requests"] = self.requests
        out["models"] = {m: c.__dict__.copy() for m, c in self.models.items()}
        return out
