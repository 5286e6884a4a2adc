"""Explanations during a ride: LLM-2 decides whether a step needs one, LLM-3 gives it.

Both run in the lane's explanation channel, one task at a time. A step whose decision
would wait behind a busy channel goes without one (a slow model must not build a queue of
stale decisions). Each step's record carries the ride's history (how long the car has been
slow or standing, the speed it has just lost), so LLM-2 can explain what a passenger
notices over several steps. A cause is explained once while it lasts (explain decisions
naming it at most :data:`SAME_CAUSE_GAP_S` apart are one cause), and a factor explained
before only after the ride's cool-down.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from explaindrive.language.explanation.decision import Decision, most_critical_factor
from explaindrive.language.explanation.explainer import Explanation, cause_present
from explaindrive.language.explanation.history import HistoryTracker
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.ride.config import RideConfig
from explaindrive.ride.jobs import DecideJob, ExplainJob
from explaindrive.ride.lane import EXPLANATION, LanguageLane, TaskKind
from explaindrive.ride.records import RideCounts, StepRecord

if TYPE_CHECKING:
    from numpy.typing import NDArray

    from explaindrive.language.stack import LanguageStack

SAME_CAUSE_GAP_S = 3.0
"""[s] explain decisions naming one factor at most this far apart are about one cause."""


class Explanations:
    """Asks LLM-2 about steps and LLM-3 for the explanations it decides on.

    Args:
        config: ride settings (deadline, cool-down).
        lane: the language lane the decisions and explanations run in.
        language: the language modules (decider, explainer).
        counts: the ride's counters.
        records: the ride's step records, which decisions and explanations are written into.
    """

    def __init__(
        self,
        config: RideConfig,
        lane: LanguageLane,
        language: LanguageStack,
        counts: RideCounts,
        records: list[StepRecord],
    ) -> None:
        self.config = config
        self.lane = lane
        self.language = language
        self.counts = counts
        self.records = records
        self.latest: dict[str, Any] | None = None
        self._explained_at: dict[str | None, float] = {}  # factor -> when last explained
        self._named_at: dict[str | None, float] = {}  # factor -> last explain decision naming it
        self._now: tuple[int, StateRecord] | None = None  # the newest step and its state
        self.history = HistoryTracker()

    def state_record(
        self, seen: NDArray[Any], change: int, yield_gap_m: float | None = None
    ) -> StateRecord:
        """The newest step's record for LLM-2 and LLM-3: what the driver saw (``seen``, the
        raw observation, and ``yield_gap_m``, the yield line perceived with it: the env's
        ``info["yield_gap_m"]``), its speed change and the ride's history, updated by this
        step."""
        record = StateRecord.from_observation(seen, change, yield_gap_m=yield_gap_m)
        history = self.history.update(record.state.v_ego, record.state.v_lim)
        return record.model_copy(update={"history": history})

    def submit_decision(self, record: StepRecord, state_record: StateRecord) -> None:
        """Ask LLM-2 about the newest step, unless the explanation channel is still busy."""
        self._now = (len(self.records) - 1, state_record)
        if self.lane.busy(EXPLANATION):
            self.counts.skipped_decisions += 1
            record.decision = {"explain": False, "skipped": "the explanation channel is busy"}
            return
        self.lane.submit(
            TaskKind.DECIDE,
            self.language.decider.decide,
            state_record,
            deadline_s=self.config.decide_deadline_s,
            context=DecideJob(state_record, len(self.records) - 1),
        )

    def on_decision(self, job: DecideJob, decision: Decision, latency_s: float) -> None:
        """Record LLM-2's decision (its task took ``latency_s`` [s]); ask LLM-3 when it says
        explain, outside the cool-down."""
        rec = self.records[job.step]
        factor = decision.factor.value if decision.factor is not None else None
        rec.decision = {
            "explain": decision.explain,
            "factor": factor,
            "backend": decision.backend,
            "fallback": decision.fallback,
            "latency_s": round(latency_s, 4),
        }
        if decision.raw_reply is not None:  # the ride log keeps what the model said
            rec.decision.update(vetoed=decision.vetoed, raw_reply=decision.raw_reply)
        rec.latency_s["decide"] = latency_s
        self.counts.fallbacks += int(decision.fallback)
        self.counts.models["decide"].add(decision.fallback, decision.vetoed)
        if not decision.explain:
            return
        self.counts.explain_decisions += 1
        named_t = self._named_at.get(factor, -math.inf)
        self._named_at[factor] = rec.t
        if rec.t - named_t <= SAME_CAUSE_GAP_S:  # the cause explained (or held back) lasts
            self.counts.suppressed_explanations += 1
            rec.decision["suppressed"] = "the same cause"
            return
        if rec.t - self._explained_at.get(factor, -math.inf) < self.config.explanation_cooldown_s:
            self.counts.suppressed_explanations += 1
            rec.decision["suppressed"] = "cool-down"
            return
        self._explained_at[factor] = rec.t
        self.lane.submit(
            TaskKind.EXPLAIN,
            self.language.explainer.explain,
            job.record,
            decision.factor,
            deadline_s=self.config.explain_deadline_s,
            context=ExplainJob(job.step),
        )

    def answer(self, question: int) -> bool:
        """Have LLM-3 explain the newest step for the passenger's "why?" (request
        ``question``): by the factor the rule engine would name, else the first braking
        factor in the state, else none (what the car does and that it is safe). A question
        is answered whatever the cool-down; ``False`` before the first step.
        """
        if self._now is None:
            return False
        step, state_record = self._now
        self.lane.submit(
            TaskKind.EXPLAIN,
            self.language.explainer.explain,
            state_record,
            most_critical_factor(state_record, self.language.cutoff_m),
            deadline_s=self.config.explain_deadline_s,
            context=ExplainJob(step, question),
        )
        return True

    def on_explanation(self, job: ExplainJob, exp: Explanation, latency_s: float) -> None:
        """Write LLM-3's explanation (its task took ``latency_s`` [s]) into the record of the
        step it explains. One that arrives after a newer step is shown only if its cause is
        still present in the newest state (a question's answer always is)."""
        rec = self.records[job.step]
        rec.explanation = {
            "text": exp.text,
            "factor": exp.factor.value if exp.factor is not None else None,
            "backend": exp.backend,
            "fallback": exp.fallback,
            "latency_s": round(latency_s, 4),
        }
        if exp.raw_reply is not None:
            rec.explanation.update(raw_reply=exp.raw_reply, vetoed=exp.vetoed)
        if job.question is not None:
            rec.explanation["question"] = job.question
        rec.latency_s["explain"] = latency_s
        self.counts.fallbacks += int(exp.fallback)
        module = self.counts.models["explain"]
        module.add(exp.fallback, exp.vetoed)
        newest = len(self.records) - 1
        if newest > job.step:
            rec.explanation["shown_t"] = self.records[newest].t
            now = self._now[1] if self._now is not None else None
            still = now is None or cause_present(now.nearby(self.language.cutoff_m), exp.factor)
            if job.question is None and not still:
                rec.explanation["shown"] = False  # its cause has gone: the passenger is spared
                module.stale += 1
                return
        self.counts.explanations += 1
        self.latest = {"t": rec.t, **rec.explanation}
