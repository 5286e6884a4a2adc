"""One passenger ride: the closed loop of commands, driving and explanations.

Each 1 s step: passenger input -> language lane (transcribe, interpret) ->
confirmation -> merged controller (fast/comfort policies, stop honoured) ->
action -> SUMO -> LLM-2 decides whether to explain -> LLM-3 explains.

The control step never waits on language. With ``realtime`` the loop is paced
at 1 step/s and language work overlaps it; otherwise the simulation
fast-forwards, pausing only while language work is pending (up to its deadline),
so that simulated and real latencies agree.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from explaindrive.agent.controller import MergedController
from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.actions import speed_change
from explaindrive.env.metrics import EpisodeMetrics
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.language.decision import Decision
from explaindrive.language.explanation import Explanation
from explaindrive.language.intent import IntentResult
from explaindrive.language.speech import AudioError
from explaindrive.language.summary import StateRecord
from explaindrive.ride.config import RideConfig
from explaindrive.ride.events import EventType
from explaindrive.ride.lane import EXPLANATION, LanguageLane, Outcome

if TYPE_CHECKING:
    from explaindrive.language.stack import LanguageStack

log = logging.getLogger(__name__)

FALLBACK_MARGIN_S = 0.2
"""[s] time a language task keeps, after a remote model's deadline, for the embedded
module to answer instead."""


@dataclass
class _Request:
    """A passenger line on its way to becoming a command."""

    id: int
    t: float
    text: str | None
    audio: Path | None
    confirm: str | None  # scripted answer: "yes" / "no" / None
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


@dataclass
class RideCounts:
    """Counters for the ride summary."""

    requests: int = 0
    understood: int = 0
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


class RideSession:
    """A ride that advances one step at a time and takes passenger input at any time.

    Args:
        config: ride settings.
        controller: the merged fast/comfort controller.
        language: the language modules.
        env: an environment to drive (built from ``config`` when omitted).

    Raises:
        ValueError: if a remote model's deadline does not fit the ride's deadlines.
    """

    def __init__(
        self,
        config: RideConfig,
        controller: MergedController,
        language: LanguageStack,
        env: UrbanDriveEnv | None = None,
    ) -> None:
        check_deadlines(config, language.remote_deadline_s)
        self.config = config
        self.controller = controller
        self.language = language
        self.env = env or UrbanDriveEnv(
            traffic_level=config.traffic_level,
            max_steps=config.max_steps,
            yellow_leader=controller.yellow_leader,  # the networks' own rule
            obs_noise=config.obs_noise,
            **config.scenario_fields(),
            render_mode="human" if config.gui else None,
        )
        self.lane = LanguageLane()
        self.counts = RideCounts()
        self.metrics = EpisodeMetrics()
        self.records: list[StepRecord] = []
        self.pending_confirmation: _Request | None = None
        self._requests = 0
        self._newest_read = 0  # the latest request understood as a command
        self._inbox: list[dict[str, Any]] = []  # passenger events of the coming step
        self._obs: NDArray[np.float32] | None = None
        self._explained_at: dict[str | None, float] = {}  # factor -> when last explained
        self.done = False
        self.latest_explanation: dict[str, Any] | None = None

    # ------------------------------------------------------------------ lifecycle
    def start(self, command: Command = Command.FAST) -> NDArray[np.float32]:
        """Reset the environment; the ride starts under ``command``."""
        obs, _ = self.env.reset(seed=self.config.seed, options={"command": command.label})
        self.controller.follow(self.env)
        self._obs = obs
        self.done = False
        return obs

    def close(self) -> None:
        """Stop SUMO and the language worker."""
        self.lane.close()
        self.env.close()

    @property
    def t(self) -> float:
        """Ride time [s]."""
        return float(len(self.records))

    @property
    def interpreting(self) -> bool:
        """Whether a passenger request is still being transcribed or interpreted."""
        return self.lane.pending_kind("interpret")

    @property
    def command(self) -> Command:
        """The confirmed command the car follows: the environment holds it, the controller
        follows it (and keeps it readable after the ride)."""
        return self.controller.command

    # ------------------------------------------------------------------ passenger input
    def say(self, text: str, confirm: str | None = None) -> int:
        """A typed passenger line; returns its request id."""
        return self._request(text=text, audio=None, confirm=confirm)

    def say_audio(self, path: str | Path, confirm: str | None = None) -> int:
        """A spoken passenger line (a WAV/FLAC/MP3 file); returns its request id."""
        return self._request(text=None, audio=Path(path), confirm=confirm)

    def answer(self, yes: bool) -> bool:
        """Answer the pending confirmation question; ``False`` if none was pending."""
        req = self.pending_confirmation
        if req is None:
            self._note({"type": EventType.ANSWER_IGNORED, "reason": "no question pending"})
            return False
        self._resolve(req, yes, source="passenger")
        return True

    def _request(self, text: str | None, audio: Path | None, confirm: str | None) -> int:
        self._requests += 1
        req = _Request(self._requests, self.t, text, audio, confirm)
        self.counts.requests += 1
        self._note(
            {
                "type": EventType.LINE,
                "id": req.id,
                "text": text,
                "audio": str(audio) if audio else None,
            }
        )
        self.lane.submit(
            "interpret",
            self._interpret,
            req,
            deadline_s=(
                self.config.audio_deadline_s if audio else self.config.interpret_deadline_s
            ),
            context={"request": req},
        )
        return req.id

    def _interpret(self, req: _Request) -> tuple[str, IntentResult | None, float, str | None]:
        """Worker side: transcribe if needed, then interpret.

        Returns (text, interpretation or None, transcription time, why there is no text).
        """
        transcript_s = 0.0
        text = req.text or ""
        if req.audio is not None:
            t0 = time.perf_counter()
            try:
                text = self.language.transcriber.transcribe(req.audio).text
            except AudioError as exc:
                return "", None, time.perf_counter() - t0, str(exc)
            transcript_s = time.perf_counter() - t0
        if not text.strip():
            return text, None, transcript_s, "empty request"
        return text, self.language.interpreter.interpret(text), transcript_s, None

    # ------------------------------------------------------------------ control step
    def step(self) -> StepRecord:
        """Advance the ride by one 1 s step.

        Raises:
            RuntimeError: if the ride is over or was not started.
        """
        if self._obs is None or self.done:
            raise RuntimeError("the ride is not running; call start()")
        self._handle(self.lane.collect(wait=not self.config.realtime))
        self.controller.follow(self.env)
        obs = self.controller.observation(self._obs)
        t0 = time.perf_counter()
        action = self.controller.act(obs)
        policy_s = time.perf_counter() - t0
        command, agent = self.controller.command, self.controller.active_agent
        next_obs, reward, terminated, truncated, info = self.env.step(action)
        self.metrics.update(info, reward)
        change = speed_change(action)
        record = StepRecord(
            t=float(info["time_s"]),
            state={n: round(float(v), 3) for n, v in zip(S.STATE_NAMES, obs, strict=True)},
            command=command.label,
            agent=agent.label,
            action=change,
            speed_mps=float(info["speed_mps"]),
            limit_mps=float(info["limit_mps"]),
            reward=float(reward),
            flags={
                k: bool(info[k])
                for k in ("collision", "red_light_run", "ped_violation", "speeding", "arrived")
            },
            passenger=self._inbox,
            latency_s={"policy": policy_s},
            shield=self._shield_event(),
        )
        self._inbox = []
        self.records.append(record)
        self._obs = next_obs
        self.done = terminated or truncated
        if command is not Command.STOP or change > 0:
            self._submit_decision(record, StateRecord.from_observation(obs, change))
        if self.done:
            self._handle(self.lane.collect(wait=True))
            record.passenger.extend(self._inbox)
            self._inbox = []
        return record

    def _shield_event(self) -> dict[str, Any] | None:
        """The shield's intervention in the step just chosen, if it replaced the network."""
        ctrl = self.controller
        if not (ctrl.use_shield and ctrl.last_override and ctrl.last_network_action is not None):
            return None
        return {"replaced": True, "network_action": speed_change(ctrl.last_network_action)}

    def _submit_decision(self, record: StepRecord, state_record: StateRecord) -> None:
        """Ask LLM-2 about this step, unless the explanation channel is still busy.

        A slow model must not build a queue of stale decisions: while the previous
        decision or explanation is still running, this step goes without one.
        """
        if self.lane.busy(EXPLANATION):
            self.counts.skipped_decisions += 1
            record.decision = {"explain": False, "skipped": "the explanation channel is busy"}
            return
        self.lane.submit(
            "decide",
            self.language.decider.decide,
            state_record,
            deadline_s=self.config.explain_deadline_s,
            context={"record": state_record, "step": len(self.records) - 1},
        )

    # ------------------------------------------------------------------ language results
    def _handle(self, outcomes: list[Outcome]) -> None:
        for out in outcomes:
            kind = out.task.kind
            if out.late or out.error:
                what = EventType.LATE if out.late else EventType.ERROR
                self.counts.late += out.late
                self.counts.errors += out.error is not None
                self._note(
                    {
                        "type": what,
                        "module": kind,
                        "latency_s": round(out.latency_s, 4),
                        "error": out.error,
                        "kept_command": self.controller.command.label,
                    }
                )
                log.warning("%s %s: %s", kind, what, out.error or f"{out.latency_s:.2f} s")
                continue
            if kind == "interpret":
                self._on_interpretation(out)
            elif kind == "decide":
                self._on_decision(out)
            elif kind == "explain":
                self._on_explanation(out)

    def _on_interpretation(self, out: Outcome) -> None:
        req: _Request = out.task.context["request"]
        text, result, transcribe_s, problem = out.result
        if req.audio is not None:
            self._note(
                {
                    "type": EventType.TRANSCRIPT,
                    "id": req.id,
                    "text": text,
                    "latency_s": round(transcribe_s, 4),
                }
            )
        if result is None:
            self.counts.rephrase += 1
            self._note(
                {
                    "type": EventType.REPHRASE,
                    "id": req.id,
                    "reason": problem,
                    "message": "Sorry, I did not catch that. Could you say it again?",
                }
            )
            return
        self.counts.fallbacks += int(result.fallback)
        self._note(
            {
                "type": EventType.INTERPRETATION,
                "id": req.id,
                **result.to_json(),
                "latency_s": round(out.latency_s, 4),
                "error": result.error,
                "raw_reply": result.raw_reply,  # for the log; the page drops it
            }
        )
        if result.intent is None:
            self.counts.rephrase += 1
            return
        if req.id < self._newest_read:
            # a later request was understood first: the passenger's last instruction counts
            self.counts.superseded += 1
            self._note({"type": EventType.SUPERSEDED, "id": req.id, "by": self._newest_read})
            return
        self.counts.understood += 1
        self._newest_read = req.id
        req.intent, req.question = result.intent, result.confirmation
        if result.intent is Command.STOP and self.config.stop_without_confirm:
            self._resolve(req, True, source="stop-without-confirm")
        elif req.confirm is not None:
            self._resolve(req, req.confirm == "yes", source="script")
        elif self.config.auto_confirm:
            self._resolve(req, True, source="auto")
        else:
            if self.pending_confirmation is not None:
                self._note({"type": EventType.SUPERSEDED, "id": self.pending_confirmation.id})
            self.pending_confirmation = req

    def _resolve(self, req: _Request, yes: bool, source: str) -> None:
        if self.pending_confirmation is req:
            self.pending_confirmation = None
        if not yes or req.intent is None:
            self.counts.cancellations += 1
            self._note(
                {
                    "type": EventType.CANCELLED,
                    "id": req.id,
                    "answer": "no",
                    "source": source,
                    "kept_command": self.controller.command.label,
                }
            )
            return
        self.counts.confirmations += 1
        before = self.controller.command
        self.env.set_command(req.intent)
        self.controller.follow(self.env)
        self._note(
            {
                "type": EventType.CONFIRMED,
                "id": req.id,
                "source": source,
                "from": before.label,
                "to": req.intent.label,
            }
        )

    def _on_decision(self, out: Outcome) -> None:
        decision: Decision = out.result
        step = out.task.context["step"]
        rec = self.records[step]
        factor = decision.factor.value if decision.factor is not None else None
        rec.decision = {
            "explain": decision.explain,
            "factor": factor,
            "backend": decision.backend,
            "fallback": decision.fallback,
            "latency_s": round(out.latency_s, 4),
        }
        if decision.raw_reply is not None:  # the ride log keeps what the model said
            rec.decision.update(vetoed=decision.vetoed, raw_reply=decision.raw_reply)
        rec.latency_s["decide"] = out.latency_s
        self.counts.fallbacks += int(decision.fallback)
        if not decision.explain:
            return
        self.counts.explain_decisions += 1
        last_t = self._explained_at.get(factor, -math.inf)
        if rec.t - last_t < self.config.explanation_cooldown_s:  # rate-limited per factor
            self.counts.suppressed_explanations += 1
            rec.decision["suppressed"] = True
            return
        self._explained_at[factor] = rec.t
        self.lane.submit(
            "explain",
            self.language.explainer.explain,
            out.task.context["record"],
            decision.factor,
            deadline_s=self.config.explain_deadline_s,
            context={"step": step},
        )

    def _on_explanation(self, out: Outcome) -> None:
        exp: Explanation = out.result
        rec = self.records[out.task.context["step"]]
        rec.explanation = {
            "text": exp.text,
            "factor": exp.factor.value if exp.factor is not None else None,
            "backend": exp.backend,
            "fallback": exp.fallback,
            "latency_s": round(out.latency_s, 4),
        }
        if exp.raw_reply is not None:
            rec.explanation["raw_reply"] = exp.raw_reply
        rec.latency_s["explain"] = out.latency_s
        self.counts.explanations += 1
        self.counts.fallbacks += int(exp.fallback)
        self.latest_explanation = {"t": rec.t, **rec.explanation}

    def _note(self, event: dict[str, Any]) -> None:
        event.setdefault("t", self.t)
        self._inbox.append(event)

    # ------------------------------------------------------------------ results
    def summary(self) -> dict[str, Any]:
        """Evaluation metrics of the ride plus the language counters."""
        res = self.metrics.result()
        return {
            "config": self.config.to_dict(),
            "metrics": res.as_dict(),
            "counts": self.counts.__dict__.copy(),
            "final_command": self.controller.command.label,
            "steps": len(self.records),
            "shield_replacements": sum(r.shield is not None for r in self.records),
        }


def check_deadlines(config: RideConfig, remote_deadline_s: float | None) -> None:
    """Check that a remote model's deadline leaves the embedded fallback time in the ride.

    Raises:
        ValueError: if ``remote_deadline_s`` plus :data:`FALLBACK_MARGIN_S` exceeds the
            interpretation or the explanation deadline.
    """
    if remote_deadline_s is None:
        return
    for name in ("interpret_deadline_s", "explain_deadline_s"):
        ride_s = getattr(config, name)
        if remote_deadline_s + FALLBACK_MARGIN_S > ride_s:
            raise ValueError(
                f"the remote model's deadline (openai.timeout_s {remote_deadline_s:g} s) plus "
                f"{FALLBACK_MARGIN_S:g} s for the embedded fallback exceeds the ride's {name} "
                f"({ride_s:g} s); lower openai.timeout_s"
            )
