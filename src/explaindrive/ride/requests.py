"""The passenger's requests: from a line to a confirmed command.

A line (:data:`~explaindrive.ride.inputs.PassengerInput`, typed or spoken) is transcribed
(when spoken) and interpreted (LLM-1) in the language lane; a command read from it is
confirmed (by the passenger, the script or the ride's settings) before the car follows it.
A confirmed command goes to the controller, which drives by it, and to the environment,
which rewards and measures by it.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from explaindrive.commands import Command
from explaindrive.language.intent.model import WHY_READING, answer_of
from explaindrive.language.speech.transcriber import AudioError
from explaindrive.ride.config import RideConfig
from explaindrive.ride.events import EventType
from explaindrive.ride.inputs import PassengerInput, SpokenLine, TypedLine
from explaindrive.ride.jobs import Interpretation, InterpretJob
from explaindrive.ride.lane import LanguageLane, TaskKind
from explaindrive.ride.records import PassengerRequest, RideCounts

if TYPE_CHECKING:
    from explaindrive.agent.controller import MergedController
    from explaindrive.env.urban_drive import UrbanDriveEnv
    from explaindrive.language.stack import LanguageStack

Note = Callable[[dict[str, Any]], None]
"""Adds a passenger event to the coming step's record."""

REPHRASE_MESSAGE = "Sorry, I did not catch that. Could you say it again?"


class PassengerRequests:
    """Takes passenger lines, has them interpreted, and applies the confirmed commands.

    Args:
        config: ride settings (deadlines, confirmation rules).
        lane: the language lane the interpretation runs in.
        language: the language modules (transcriber, interpreter).
        controller: drives by the confirmed command.
        env: rewards and measures by the confirmed command.
        counts: the ride's counters.
        note: adds a passenger event to the coming step's record.
        clock: the ride time [s].
    """

    def __init__(
        self,
        config: RideConfig,
        lane: LanguageLane,
        language: LanguageStack,
        controller: MergedController,
        env: UrbanDriveEnv,
        counts: RideCounts,
        note: Note,
        clock: Callable[[], float],
    ) -> None:
        self.config = config
        self.lane = lane
        self.language = language
        self.controller = controller
        self.env = env
        self.counts = counts
        self._note = note
        self._clock = clock
        self.pending_confirmation: PassengerRequest | None = None
        self._requests = 0
        self._newest_read = 0  # the latest request understood as a command
        self._held_answer: bool | None = None  # a yes/no heard before its question
        self.on_question: Callable[[int], object] | None = None
        """Answers a "why?" question (the request's id): set by the session."""

    def submit(self, line: PassengerInput, confirm: bool | None = None) -> int:
        """Queue a line for interpretation; returns its request id.

        Args:
            line: what the passenger typed or spoke.
            confirm: the scripted answer to the confirmation question; ``None`` leaves it to
                the ride's settings or the passenger.

        Raises:
            TypeError: if ``confirm`` is not a bool or ``None`` (a "yes"/"no" string would
                read as yes either way).
        """
        if confirm is not None and not isinstance(confirm, bool):
            raise TypeError(f"confirm must be True, False or None, got {confirm!r}")
        self._requests += 1
        req = PassengerRequest(self._requests, self._clock(), line, confirm)
        self.counts.lines += 1
        text: str | None = None
        audio: str | None = None
        match line:
            case TypedLine(typed):
                text, deadline_s = typed, self.config.interpret_deadline_s
            case SpokenLine(path):
                audio, deadline_s = str(path), self.config.audio_deadline_s
        self._note({"type": EventType.LINE, "id": req.id, "text": text, "audio": audio})
        self.lane.submit(
            TaskKind.INTERPRET,
            self._interpret,
            req,
            deadline_s=deadline_s,
            context=InterpretJob(req),
        )
        return req.id

    def answer(self, yes: bool) -> bool:
        """Answer the pending confirmation question; ``False`` if none was pending."""
        req = self.pending_confirmation
        if req is None:
            self._note({"type": EventType.ANSWER_IGNORED, "reason": "no question pending"})
            return False
        self._resolve(req, yes, source="passenger")
        return True

    def _interpret(self, req: PassengerRequest) -> Interpretation:
        """Worker side: transcribe if needed, then interpret."""
        match req.line:
            case TypedLine(text):
                transcript_s = 0.0
            case SpokenLine(audio):
                t0 = time.perf_counter()
                try:
                    text = self.language.transcriber.transcribe(audio).text
                except AudioError as exc:
                    return Interpretation("", None, time.perf_counter() - t0, str(exc))
                transcript_s = time.perf_counter() - t0
        if not text.strip():
            return Interpretation(text, None, transcript_s, "empty request")
        return Interpretation(text, self.language.interpreter.interpret(text), transcript_s, None)

    def on_interpretation(self, job: InterpretJob, heard: Interpretation, latency_s: float) -> None:
        """Log what was heard and understood; confirm the command or ask the question.

        Args:
            job: the interpreted request's job.
            heard: what the interpretation worker returned.
            latency_s: the task's wall time [s].
        """
        req = job.request
        result = heard.result
        self._note_heard(req, heard, latency_s)
        if result is None:
            return
        answer = answer_of(result.reading)
        if answer is not None:
            self._hear_answer(answer)
            return
        if result.reading == WHY_READING and self.on_question is not None:
            # a question, not a request: the command stays
            self.counts.questions += 1
            self.on_question(req.id)
            return
        intent = result.intent if result.intent is not None else result.ask
        if intent is None:
            self.counts.rephrase += 1
            return
        if req.id < self._newest_read:
            # a later request was understood first: the passenger's last instruction counts
            self.counts.superseded += 1
            self._note({"type": EventType.SUPERSEDED, "id": req.id, "by": self._newest_read})
            return
        self.counts.understood += 1
        self.counts.asked_stop += int(result.intent is None)
        self._newest_read = req.id
        # a STOP asked about (not read) waits for a yes: stop_without_confirm is for STOPs read
        req.intent, req.question = intent, result.confirmation
        if result.intent is Command.STOP and self.config.stop_without_confirm:
            self._resolve(req, True, source="stop-without-confirm")
        elif req.confirm is not None:
            self._resolve(req, req.confirm, source="script")
        elif self.config.auto_confirm:
            self._resolve(req, True, source="auto")
        else:
            if self.pending_confirmation is not None:
                self._note({"type": EventType.SUPERSEDED, "id": self.pending_confirmation.id})
            self.pending_confirmation = req
            if self._held_answer is not None:
                yes, self._held_answer = self._held_answer, None
                self.answer(yes)

    def _note_heard(self, req: PassengerRequest, heard: Interpretation, latency_s: float) -> None:
        """Log the transcript of a spoken line, and the interpretation or why there is none."""
        if isinstance(req.line, SpokenLine):
            self._note(
                {
                    "type": EventType.TRANSCRIPT,
                    "id": req.id,
                    "text": heard.text,
                    "latency_s": round(heard.transcribe_s, 4),
                }
            )
        result = heard.result
        if result is None:
            self.counts.rephrase += 1
            self._note(
                {
                    "type": EventType.REPHRASE,
                    "id": req.id,
                    "reason": heard.problem,
                    "message": REPHRASE_MESSAGE,
                }
            )
            return
        self.counts.fallbacks += int(result.fallback)
        self.counts.models["interpret"].add(result.fallback, result.overruled)
        self._note(
            {
                "type": EventType.INTERPRETATION,
                "id": req.id,
                **result.to_json(),
                "latency_s": round(latency_s, 4),
                "error": result.error,
                "raw_reply": result.raw_reply,  # for the log; the page drops it
            }
        )

    def _hear_answer(self, yes: bool) -> None:
        """A line read as yes or no answers the pending question; heard while a request is
        still being interpreted (several workers: the answer may be read first), it waits
        for that request's question."""
        self.counts.answers += 1
        if self.pending_confirmation is not None:
            self.answer(yes)
        elif self.lane.pending_kind(TaskKind.INTERPRET):
            self._held_answer = yes
        else:
            self.answer(yes)  # noted as ignored: no question pending

    def _resolve(self, req: PassengerRequest, yes: bool, source: str) -> None:
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
