"""Live terminal view of a ride (rich)."""

from __future__ import annotations

from rich.panel import Panel
from rich.table import Table

from explaindrive.env.state import SENSOR_RANGE_M, LightState
from explaindrive.ride.events import EventType
from explaindrive.ride.records import StepRecord
from explaindrive.ride.session import RideSession


def _dist(value: float) -> str:
    return "-" if value >= SENSOR_RANGE_M else f"{value:.0f} m"


def render(session: RideSession, rec: StepRecord | None) -> Panel:
    """One frame: state, command, action, latest passenger line, question and explanation."""
    table = Table.grid(padding=(0, 2))
    table.add_column(justify="right", style="bold")
    table.add_column()
    if rec is None:
        table.add_row("status", "starting...")
        return Panel(table, title="ExplainDrive ride")
    s = rec.state
    light = (
        "-"
        if s["d_tl"] >= SENSOR_RANGE_M
        else (f"{LightState(int(s['tls'])).label} at {s['d_tl']:.0f} m")
    )
    table.add_row("time", f"{rec.t:.0f} s")
    table.add_row("speed / limit", f"{rec.speed_mps:.1f} / {rec.limit_mps:.1f} m/s")
    table.add_row("leader gap", _dist(s["d_lead"]))
    table.add_row("traffic light", light)
    table.add_row("pedestrian crossing", _dist(s["d_cross"]))
    table.add_row("command", f"{rec.command} (agent: {rec.agent})")
    table.add_row("action", f"{rec.action:+d} m/s")
    line = next(
        (
            e
            for r in reversed(session.records)
            for e in reversed(r.passenger)
            if e["type"] == EventType.LINE
        ),
        None,
    )
    if line:
        table.add_row("passenger", str(line.get("text") or line.get("audio")))
    pending = session.pending_confirmation
    if pending is not None and pending.question:
        table.add_row("question", pending.question)
    if session.latest_explanation:
        exp = session.latest_explanation
        table.add_row("explanation", f"[{exp['t']:.0f} s] {exp['text']}")
    return Panel(table, title="ExplainDrive ride")
