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
import time
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
from explaindrive.language.explanation.decision import Decision
from explaindrive.language.explanation.explainer import Explanation
from explaindrive.ride.config import RideConfig
from explaindrive.ride.events import EventType
from explaindrive.ride.explaining import Explanations
from explaindrive.ride.inputs import PassengerInput, SpokenLine, TypedLine
from explaindrive.ride.jobs import DecideJob, ExplainJob, Interpretation, InterpretJob
from explaindrive.ride.lane import LanguageLane, Outcome, TaskKind
from explaindrive.ride.records import PassengerRequest, RideCounts, StepRecord
from explaindrive.ride.requests import PassengerRequests

if TYPE_CHECKING:
    from explaindrive.language.stack import LanguageStack

log = logging.getLogger(__name__)

__all__ = ["FALLBACK_MARGIN_S", "RideCounts", "RideSession", "StepRecord", "check_deadlines"]

STEP_FLAGS: tuple[str, ...] = (
    "collision", "red_light_run", "ped_violation", "yield_violation", "speeding", "arrived",
)  # fmt: skip
"""The step ``info`` flags a ride's step record keeps."""
FALLBACK_MARGIN_S = 0.2
"""[s] time a language task keeps, after a remote model's deadline, for the embedded
module to answer instead."""


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
        self._inbox: list[dict[str, Any]] = []  # passenger events of the coming step
        self._obs: NDArray[np.float32] | None = None
        self._yield_gap_m: float | None = None  # perceived with _obs (info["yield_gap_m"])
        self.done = False
        self.requests = PassengerRequests(
            config, self.lane, language, controller, self.env, self.counts, self._note,
            clock=lambda: self.t,
        )  # fmt: skip
        self.explanations = Explanations(config, self.lane, language, self.counts, self.records)
        self.requests.on_question = self.explanations.answer

    # ------------------------------------------------------------------ lifecycle
    def start(self, command: Command = Command.FAST) -> NDArray[np.float32]:
        """Reset the environment; the ride starts under ``command``."""
        obs, info = self.env.reset(seed=self.config.seed, options={"command": command.label})
        self.controller.begin(self.env.config.obs_noise[1])  # the sensor it drives with
        self.controller.follow(self.env)
        self._obs, self._yield_gap_m = obs, float(info["yield_gap_m"])
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
        return self.lane.pending_kind(TaskKind.INTERPRET)

    @property
    def thinking(self) -> list[str]:
        """The language modules at work now (``interpret``, ``decide``, ``explain``)."""
        modules = {
            TaskKind.TRANSCRIBE: "interpret",
            TaskKind.INTERPRET: "interpret",
            TaskKind.DECIDE: "decide",
            TaskKind.EXPLAIN: "explain",
        }
        return sorted({modules[k] for k in self.lane.working()})

    @property
    def language(self) -> LanguageStack:
        """The language modules (replacing them reaches the requests and the explanations)."""
        return self.requests.language

    @language.setter
    def language(self, language: LanguageStack) -> None:
        self.requests.language = language
        self.explanations.language = language

    @property
    def pending_confirmation(self) -> PassengerRequest | None:
        """The interpreted request waiting for the passenger's yes or no."""
        return self.requests.pending_confirmation

    @property
    def latest_explanation(self) -> dict[str, Any] | None:
        """The newest explanation given, with its ride time."""
        return self.explanations.latest

    @property
    def command(self) -> Command:
        """The confirmed command the car follows: the environment holds it, the controller
        follows it (and keeps it readable after the ride)."""
        return self.controller.command

    # ------------------------------------------------------------------ passenger input
    def hear(self, line: PassengerInput, confirm: bool | None = None) -> int:
        """A passenger line, typed or spoken; returns its request id.

        Args:
            line: what the passenger typed or spoke.
            confirm: the scripted answer to the confirmation question (yes: ``True``);
                ``None`` leaves it to the ride's settings or the passenger.
        """
        return self.requests.submit(line, confirm)

    def say(self, text: str, confirm: bool | None = None) -> int:
        """A typed passenger line (:meth:`hear` of a :class:`TypedLine`)."""
        return self.hear(TypedLine(text), confirm)

    def say_audio(self, path: str | Path, confirm: bool | None = None) -> int:
        """A spoken passenger line, a WAV/FLAC/MP3 file (:meth:`hear` of a
        :class:`SpokenLine`)."""
        return self.hear(SpokenLine(Path(path)), confirm)

    def answer(self, yes: bool) -> bool:
        """Answer the pending confirmation question; ``False`` if none was pending."""
        return self.requests.answer(yes)

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
        seen = self.controller.last_seen  # what the network read: explained and logged
        if seen is None:
            seen = obs
        command, agent = self.controller.command, self.controller.active_agent
        next_obs, reward, terminated, truncated, info = self.env.step(action)
        self.metrics.update(info, reward)
        change = speed_change(action)
        record = StepRecord(
            t=float(info["time_s"]),
            state={n: round(float(v), 3) for n, v in zip(S.STATE_NAMES, seen, strict=True)},
            command=command.label,
            agent=agent.label,
            action=change,
            speed_mps=float(info["speed_mps"]),
            limit_mps=float(info["limit_mps"]),
            reward=float(reward),
            flags={k: bool(info[k]) for k in STEP_FLAGS},
            passenger=self._inbox,
            latency_s={"policy": policy_s},
            shield=self._shield_event(),
        )
        self._inbox = []
        self.records.append(record)
        yield_gap_m = self._yield_gap_m  # the yield line seen with `seen`
        self._obs, self._yield_gap_m = next_obs, float(info["yield_gap_m"])
        self.done = terminated or truncated
        state_record = self.explanations.state_record(seen, change, yield_gap_m)
        if command is not Command.STOP or change > 0:
            self.explanations.submit_decision(record, state_record)
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

    # ------------------------------------------------------------------ language results
    def _handle(self, outcomes: list[Outcome]) -> None:
        """Hand each finished task to the owner of its job; log the late and the failed."""
        for out in outcomes:
            if out.late or out.error:
                self._note_missed(out)
                continue
            match out.task.context, out.result:
                case InterpretJob() as job, Interpretation() as heard:
                    self.requests.on_interpretation(job, heard, out.latency_s)
                case DecideJob() as job, Decision() as decision:
                    self.explanations.on_decision(job, decision, out.latency_s)
                case ExplainJob() as job, Explanation() as explanation:
                    self.explanations.on_explanation(job, explanation, out.latency_s)
                case job, result:
                    raise TypeError(
                        f"{type(job).__name__} came back with a {type(result).__name__}"
                    )

    def _note_missed(self, out: Outcome) -> None:
        """Log a task that came back late or failed; the car keeps its command."""
        kind = out.task.kind
        what = EventType.LATE if out.late else EventType.ERROR
        self.counts.late += out.late
        module = "interpret" if kind is TaskKind.TRANSCRIBE else kind.value
        self.counts.models[module].late += out.late
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
            "counts": self.counts.to_json(),
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
    for name in ("interpret_deadline_s", "decide_deadline_s", "explain_deadline_s"):
        ride_s = getattr(config, name)
        if remote_deadline_s + FALLBACK_MARGIN_S > ride_s:
            raise ValueError(
                f"the remote model's deadline (openai.timeout_s {remote_deadline_s:g} s) plus "
                f"{FALLBACK_MARGIN_S:g} s for the embedded fallback exceeds the ride's {name} "
                f"({ride_s:g} s); lower openai.timeout_s"
            )
