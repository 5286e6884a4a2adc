"""Test doubles for a ride: a scripted controller and scripted language modules."""

from __future__ import annotations

import time
from pathlib import Path
from typing import ClassVar

import numpy as np

from explaindrive.commands import Command
from explaindrive.env.lights import DEFAULT_YELLOW_LEADER
from explaindrive.env.scripted import CautiousDriver
from explaindrive.env.state import CMD
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.language.explanation.decision import (
    Conflict,
    Decision,
    ExplanationDecider,
    Factor,
)
from explaindrive.language.explanation.explainer import Explainer, Explanation
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.language.intent.interpreter import (
    IntentInterpreter,
    IntentResult,
    format_confirmation,
)
from explaindrive.language.speech.transcriber import Transcript
from explaindrive.language.stack import LanguageStack


class ScriptedController:
    """The merged-controller interface over the cautious rule-based driver."""

    def __init__(self, yellow_leader: str = DEFAULT_YELLOW_LEADER) -> None:
        self.command = Command.FAST
        self.active_agent = Command.FAST
        self.yellow_leader = yellow_leader
        self.driver = CautiousDriver()
        self.use_shield = False
        self.last_override = False
        self.last_network_action: int | None = None
        self.speed_noise_sd_mps: float | None = None  # set when a ride begins
        self.last_seen: np.ndarray | None = None

    def begin(self, speed_noise_sd_mps: float = 0.0) -> None:
        self.speed_noise_sd_mps = speed_noise_sd_mps

    def set_command(self, command: Command | str) -> None:
        cmd = Command.parse(command)
        if cmd is not Command.STOP:
            self.active_agent = cmd
        self.command = cmd

    def follow(self, env: UrbanDriveEnv) -> None:
        self.set_command(env.command)

    def observation(self, obs: np.ndarray) -> np.ndarray:
        x = np.array(obs, dtype=np.float32)
        x[CMD] = float(self.command)
        return x

    def act(self, obs: np.ndarray) -> int:
        self.last_seen = obs
        return self.driver(obs)


class KeywordInterpreter(IntentInterpreter):
    """Maps keywords to commands, ``yes`` / ``no`` alone to answers, a line starting with
    ``why`` to a question, a line with ``maybe out`` to a STOP asked about; ``slow`` in the
    text makes it sleep, ``crash`` raise."""

    name = "fake"
    words: ClassVar[dict[str, Command]] = {
        "hurry": Command.FAST,
        "stop": Command.STOP,
        "gently": Command.COMFORT,
    }

    def __init__(self, delay_s: float = 0.0) -> None:
        self.delay_s = delay_s

    def interpret(self, text: str) -> IntentResult:
        if "crash" in text:
            raise RuntimeError("model exploded")
        if "slow" in text:
            time.sleep(self.delay_s)
        if text.strip().lower().startswith("why"):
            return IntentResult(None, "Rephrase?", self.name, False, 0.0, {}, reading="why")
        if text.strip().lower() in ("yes", "no"):
            answer = text.strip().lower()
            return IntentResult(None, "Rephrase?", self.name, False, 0.0, {}, reading=answer)
        if "maybe out" in text.lower():
            question = format_confirmation(Command.STOP)
            return IntentResult(
                None, question, self.name, False, 0.0, {}, reading="none", ask=Command.STOP
            )
        intent = next((c for w, c in self.words.items() if w in text.lower()), None)
        question = format_confirmation(intent) if intent is not None else "Could you rephrase?"
        reading = intent.label if intent is not None else "none"
        return IntentResult(intent, question, self.name, False, 0.0, {}, reading=reading)


class BrakingDecider(ExplanationDecider):
    """Explains every deceleration under fast, naming the speed limit (a cause always
    present, so no explanation of it comes too late)."""

    name = "fake"

    def decide(self, record: StateRecord) -> Decision:
        explain = record.request == "fast" and record.action < 0
        factor = Factor.SPEED_LIMIT if explain else None
        conflict = Conflict.SLOWS if explain else Conflict.NONE
        return Decision(explain, factor, conflict, "test", self.name)


class SleepyDecider(BrakingDecider):
    """:class:`BrakingDecider` that takes ``delay_s`` per decision (a slow remote model)."""

    def __init__(self, delay_s: float) -> None:
        self.delay_s = delay_s

    def decide(self, record: StateRecord) -> Decision:
        time.sleep(self.delay_s)
        return super().decide(record)


class EchoExplainer(Explainer):
    name = "fake"

    def explain(self, record: StateRecord, factor: Factor | None) -> Explanation:
        return Explanation(f"slowing for {factor}", factor, self.name)


class FileNameTranscriber:
    """Stands in for Whisper: the file's name is what was 'said' ("go_faster.wav")."""

    def load(self) -> None:
        pass

    def transcribe(self, path: str | Path) -> Transcript:
        return Transcript(Path(path).stem.replace("_", " "), 1.0, 0.0, "en")


def fake_language(
    delay_s: float = 0.0,
    decider: ExplanationDecider | None = None,
    remote_deadline_s: float | None = None,
) -> LanguageStack:
    return LanguageStack(
        "fake",
        KeywordInterpreter(delay_s),
        decider or BrakingDecider(),
        EchoExplainer(),
        FileNameTranscriber(),
        remote_deadline_s,
    )
