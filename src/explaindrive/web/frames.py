"""The message a page gets after each step: the car, the scene, the passenger's events."""

from __future__ import annotations

from typing import Any

from explaindrive.jsonsafe import finite
from explaindrive.redact import redact, redact_json
from explaindrive.ride.records import StepRecord
from explaindrive.ride.session import RideSession
from explaindrive.web.scene import Scene, snapshot

EXPLANATION_SCAN_STEPS = 30  # explanations attach to earlier steps; look this far back


def step_frame(
    session: RideSession, record: StepRecord, ride: int, scene: Scene, explained: set[int]
) -> dict[str, Any]:
    """The frame of the step just driven, with explanations not yet published.

    Args:
        session: the ride.
        record: the step just driven.
        ride: the ride's number.
        scene: the static road scene.
        explained: steps whose explanation was published; updated here.
    """
    explanations = []
    first = max(0, len(session.records) - EXPLANATION_SCAN_STEPS)
    for index in range(first, len(session.records)):
        exp = session.records[index].explanation
        if exp is not None and index not in explained:
            explained.add(index)
            if exp.get("shown") is False:  # came after its cause had gone
                continue
            explanations.append(
                {
                    "t": session.records[index].t,
                    "text": redact(exp["text"]),
                    "factor": exp["factor"],
                }
            )
    pending = session.pending_confirmation
    return finite(
        {
            "type": "frame",
            "ride": ride,
            "t": record.t,
            "command": record.command,
            "agent": record.agent,
            "action": record.action,
            "speed_mps": round(record.speed_mps, 3),
            "limit_mps": round(record.limit_mps, 3),
            "state": record.state,
            "flags": record.flags,
            "passenger": redact_json([public_event(e) for e in record.passenger]),
            "question": _redacted(pending.question) if pending is not None else None,
            "explanations": explanations,
            "thinking": session.thinking,
            "models": session.counts.to_json()["models"],
            "scene": snapshot(session.env.sumo, scene),
        }
    )


def _redacted(text: str | None) -> str | None:
    """``text`` with secrets masked (``None`` stays ``None``)."""
    return redact(text) if text is not None else None


def public_event(event: dict[str, Any]) -> dict[str, Any]:
    """A passenger event without server file paths or a remote model's raw reply."""
    event = {k: v for k, v in event.items() if k != "raw_reply"}
    if event.get("audio"):
        return {**event, "audio": "uploaded recording"}
    return event
