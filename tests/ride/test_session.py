"""The ride loop with a scripted controller and scripted language modules (live SUMO)."""

from __future__ import annotations

import json
import time

import pytest

from explaindrive.commands import Command
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.ride.config import RideConfig
from explaindrive.ride.events import EventType
from explaindrive.ride.explaining import SAME_CAUSE_GAP_S
from explaindrive.ride.inputs import TypedLine
from explaindrive.ride.runner import run_ride
from explaindrive.ride.script import ScriptLine
from explaindrive.ride.session import RideSession, check_deadlines

from .fakes import ScriptedController, SleepyDecider, fake_language


def make_session(**overrides) -> RideSession:
    cfg = {"traffic_level": 0.5, "seed": 3, "max_steps": 120, **overrides}
    return RideSession(RideConfig(**cfg), ScriptedController(), fake_language(delay_s=0.5))


def line(t: float, say: str, confirm: str | None = None) -> ScriptLine:
    return ScriptLine(t=t, say=say, confirm=confirm)


def events(session: RideSession, kind: str) -> list[dict]:
    return [e for r in session.records for e in r.passenger if e["type"] == kind]


def test_confirmed_commands_take_effect_on_the_next_step(tmp_path):
    session = make_session()
    script = [
        line(0, "please hurry", "yes"),
        line(20, "stop now", "yes"),
        line(40, "go gently", "no"),
        line(45, "go gently", "yes"),
    ]
    out = run_ride(session, script, tmp_path)
    cmds = [r.command for r in session.records]
    assert cmds[19] == "fast" and cmds[20] == "stop"  # line at t=20, applied before step 21
    assert cmds[44] == "stop" and cmds[45] == "comfort"
    assert [e["to"] for e in events(session, "confirmed")] == ["fast", "stop", "comfort"]
    assert len(events(session, "cancelled")) == 1  # the "no" kept stop
    stop_steps = [r for r in session.records if r.command == "stop"]
    assert stop_steps[-1].speed_mps == 0.0
    c = session.counts
    assert (c.requests, c.confirmations, c.cancellations) == (4, 3, 1)
    rows = [json.loads(x) for x in out.events.read_text().splitlines()]
    assert len(rows) == len(session.records)  # one line per step, none lost
    assert rows[20]["command"] == "stop" and set(rows[0]["state"]) >= {"v_ego", "d_tl"}
    assert {e["type"] for row in rows for e in row["passenger"]} <= set(EventType)
    summary = json.loads(out.summary.read_text())
    assert summary["counts"]["confirmations"] == 3
    assert summary["metrics"]["collisions"] == 0
    assert out.figure.stat().st_size > 10_000


def test_late_failed_and_garbage_requests_keep_the_command(tmp_path):
    session = make_session(interpret_deadline_s=0.2, max_steps=40)
    script = [
        line(0, "hurry", "yes"),
        line(5, "slow down, hurry", "yes"),
        line(10, "crash the model"),
        line(15, "play some music"),
        line(20, ""),
    ]
    run_ride(session, script, tmp_path)
    assert all(r.command == "fast" for r in session.records)
    late = events(session, "late")
    assert late[0]["module"] == "interpret" and late[0]["kept_command"] == "fast"
    assert events(session, "error")[0]["error"] == "RuntimeError: model exploded"
    assert session.counts.rephrase == 2  # music and the empty line
    assert (session.counts.late, session.counts.errors) == (1, 1)


def test_unconfirmed_question_waits_for_the_passenger():
    session = make_session(max_steps=30)
    session.start()
    session.say("stop please")
    session.step()
    session.step()
    assert session.pending_confirmation is not None
    assert session.pending_confirmation.question == "You want me to stop, is this correct?"
    assert session.pending_confirmation.line == TypedLine("stop please")
    assert session.pending_confirmation.confirm is None
    assert session.command is Command.FAST
    assert session.answer(True)
    session.step()
    assert session.records[-1].command == "stop"
    assert not session.answer(False)  # nothing pending any more
    session.close()


def test_a_line_read_as_yes_answers_the_question_and_one_read_as_no_cancels():
    session = make_session(max_steps=30)
    session.start()
    session.say("stop please")
    session.step()
    session.step()
    assert session.pending_confirmation is not None
    session.say("yes")  # LLM-1 reads it as an answer, not a request
    session.step()
    session.step()
    assert session.pending_confirmation is None
    assert session.records[-1].command == "stop"
    session.say("hurry")
    session.step()
    session.step()
    session.say("no")
    session.step()
    session.step()
    assert session.pending_confirmation is None
    assert session.records[-1].command == "stop"  # cancelled: the STOP stands
    assert session.counts.cancellations == 1
    session.close()


def test_a_why_question_is_answered_by_an_explanation_and_leaves_the_command():
    session = make_session(max_steps=30)
    session.start()
    for _ in range(3):
        session.step()
    session.say("why are we going like this?")
    for _ in range(5):
        session.step()
        time.sleep(0.02)
    answers = [r for r in session.records if r.explanation and "question" in r.explanation]
    assert len(answers) == 1 and answers[0].explanation["question"] == 1
    assert answers[0].explanation["text"].startswith("slowing for")  # the fake explainer
    assert (session.counts.questions, session.counts.requests, session.counts.rephrase) == (1, 0, 0)
    assert session.pending_confirmation is None
    assert all(r.command == "fast" for r in session.records)
    session.close()


def test_an_answer_read_before_its_question_waits_for_it():
    session = make_session(max_steps=60)
    session.start()
    session.say("stop, slowly")  # "slow": interpreted in 0.5 s
    session.say("yes")  # read at once, while the request is still being interpreted
    for _ in range(40):
        session.step()
        time.sleep(0.05)
    assert session.pending_confirmation is None
    assert session.records[-1].command == "stop"
    assert [e["to"] for e in events(session, "confirmed")] == ["stop"]
    session.close()


def test_a_scripted_no_cancels_and_a_yes_no_string_is_refused():
    session = make_session(max_steps=30)
    session.start()
    session.say("stop please", confirm=False)
    session.step()
    session.step()
    assert session.pending_confirmation is None and session.command is Command.FAST
    (cancelled,) = events(session, "cancelled")
    assert (cancelled["source"], cancelled["kept_command"]) == ("script", "fast")
    with pytest.raises(TypeError, match="confirm must be True, False or None, got 'no'"):
        session.say("stop please", confirm="no")  # type: ignore[arg-type]
    assert session.counts.requests == 1
    session.close()


def test_stop_without_confirm_and_auto_confirm():
    session = make_session(stop_without_confirm=True, max_steps=30)
    session.start()
    session.say("stop")
    session.step()
    session.step()
    assert session.records[-1].command == "stop" and session.pending_confirmation is None
    session.close()


def test_a_stop_asked_about_waits_for_the_passengers_yes():
    # even where a STOP read is applied at once, a STOP asked about waits for the answer
    session = make_session(stop_without_confirm=True, max_steps=30)
    session.start()
    session.say("maybe out here")
    for _ in range(3):
        session.step()
    assert session.command is Command.FAST and session.pending_confirmation is not None
    assert session.pending_confirmation.question == "You want me to stop, is this correct?"
    assert session.counts.asked_stop == 1
    session.say("yes")
    session.step()
    session.step()
    assert session.records[-1].command == "stop" and session.pending_confirmation is None
    (interpretation,) = events(session, "interpretation")[:1]
    assert (interpretation["intent"], interpretation["ask"]) == (None, "stop")
    session.close()


def test_explanations_repeat_only_on_a_new_reason_or_after_cooldown(tmp_path):
    session = make_session(explanation_cooldown_s=1000.0, max_steps=150)
    run_ride(session, [line(0, "hurry", "yes")], tmp_path)
    c = session.counts
    assert c.explain_decisions >= 2
    assert c.explanations == 1  # one reason, endless cool-down
    assert c.suppressed_explanations == c.explain_decisions - 1
    session2 = make_session(explanation_cooldown_s=0.0, max_steps=150)
    run_ride(session2, [line(0, "hurry", "yes")], tmp_path / "b")
    # without a cool-down, each cause is explained once while it lasts: an explain decision
    # naming the factor of one at most SAME_CAUSE_GAP_S before is the same cause
    named: dict[str, float] = {}
    causes = 0
    for r in session2.records:
        if r.decision and r.decision.get("explain"):
            f = r.decision["factor"]
            causes += r.t - named.get(f, -1e9) > SAME_CAUSE_GAP_S
            named[f] = r.t
    assert causes >= 1 and session2.counts.explanations == causes


def test_step_after_the_end_is_refused(tmp_path):
    session = make_session(max_steps=3)
    run_ride(session, [], tmp_path)
    with pytest.raises(RuntimeError, match="not running"):
        session.step()


def test_typed_yes_waits_for_its_question(tmp_path):
    """Interactive input: a 'yes' typed before the question arrives answers it."""
    import queue

    typed: queue.Queue[str] = queue.Queue()
    typed.put("stop please")
    typed.put("yes")
    session = make_session(max_steps=10)
    run_ride(session, [], tmp_path, typed=typed)
    assert [e["to"] for e in events(session, "confirmed")] == ["stop"]
    assert session.counts.requests == 1  # "yes" was not taken for a new request
    assert session.records[-1].command == "stop"


def test_spoken_and_typed_lines_arrive_typed(tmp_path):
    """Interactive input: a recording is transcribed; text that looks like a file name is
    read as text."""
    import queue

    from explaindrive.ride.inputs import PassengerInput, SpokenLine, TypedLine

    lines: queue.Queue[PassengerInput | str] = queue.Queue()
    lines.put(SpokenLine(tmp_path / "please_stop.wav"))
    lines.put(TypedLine("@audio:hurry.wav"))
    session = make_session(max_steps=10, auto_confirm=True)
    run_ride(session, [], tmp_path / "ride", typed=lines)
    assert [e["text"] for e in events(session, "line")] == [None, "@audio:hurry.wav"]
    assert [e["text"] for e in events(session, "transcript")] == ["please stop"]
    assert session.counts.requests == 2


def test_a_later_request_understood_first_wins():
    """'hurry (slow model)' then 'stop': the stop is read first; the older fast is dropped."""
    session = make_session(realtime=True, max_steps=20)
    session.start()
    session.say("hurry, slow model", confirm=True)  # read in 0.5 s
    session.say("stop", confirm=True)  # read at once, in a worker of its own
    time.sleep(0.2)
    session.step()
    assert session.command is Command.STOP
    time.sleep(0.5)
    session.step()
    session.step()
    assert session.command is Command.STOP
    (stale,) = [e for r in session.records for e in r.passenger if e["type"] == "superseded"]
    assert stale == {"type": "superseded", "id": 1, "by": 2, "t": 1.0}
    assert (session.counts.superseded, session.counts.confirmations) == (1, 1)
    session.close()


def test_a_slow_decider_skips_decisions_instead_of_queueing_them():
    cfg = RideConfig(traffic_level=0.5, seed=3, max_steps=20, realtime=True)
    language = fake_language(decider=SleepyDecider(0.35))
    session = RideSession(cfg, ScriptedController(), language)
    session.start()
    for _ in range(6):
        session.step()
        time.sleep(0.2)  # a step every 0.2 s: a decision takes 0.35 s
    session.close()
    skipped = [r for r in session.records if r.decision and r.decision.get("skipped")]
    decided = [r for r in session.records if r.decision and "backend" in r.decision]
    assert session.counts.skipped_decisions == len(skipped) >= 2
    assert len(decided) >= 2 and session.counts.late == 0


def test_a_remote_deadline_must_leave_room_for_the_fallback():
    check_deadlines(RideConfig(), None)
    check_deadlines(RideConfig(), 3.8)  # 3.8 + 0.2 fits the 4 s deadlines
    with pytest.raises(ValueError, match=r"interpret_deadline_s \(4 s\)"):
        check_deadlines(RideConfig(), 3.81)
    with pytest.raises(ValueError, match=r"decide_deadline_s \(2 s\)"):
        check_deadlines(RideConfig(decide_deadline_s=2.0), 1.9)
    with pytest.raises(ValueError, match=r"explain_deadline_s \(0\.5 s\)"):
        check_deadlines(RideConfig(explain_deadline_s=0.5), 0.4)
    with pytest.raises(ValueError, match=r"lower openai\.timeout_s"):
        RideSession(RideConfig(), ScriptedController(), fake_language(remote_deadline_s=3.9))


@pytest.mark.parametrize("rule", ["always", "decided"])
def test_the_ride_drives_in_the_networks_yellow_rule(rule):
    session = RideSession(RideConfig(), ScriptedController(rule), fake_language())
    try:
        assert session.env.config.yellow_leader == rule
    finally:
        session.env.close()


def test_a_ride_begins_the_controller_with_its_speed_sensor_s_noise():
    session = make_session(obs_noise=(1.0, 0.3), max_steps=3)
    try:
        assert session.controller.speed_noise_sd_mps is None
        session.start()
        assert session.controller.speed_noise_sd_mps == 0.3
    finally:
        session.close()


class EstimatingController(ScriptedController):
    """Reads its speed as 1.25 m/s whatever the sensor says, as a speed estimate would."""

    def act(self, obs):  # type: ignore[no-untyped-def]
        action = super().act(obs)
        self.last_seen = obs.copy()
        self.last_seen[1] = 1.25
        return action


def test_the_log_and_the_explanations_hold_what_the_network_read():
    session = RideSession(
        RideConfig(traffic_level=0.5, seed=3, max_steps=4), EstimatingController(),
        fake_language(),
    )  # fmt: skip
    try:
        session.start()
        records = [session.step() for _ in range(4)]
    finally:
        session.close()
    assert [r.state["v_ego"] for r in records] == [1.25] * 4
    assert [r.speed_mps for r in records] != [1.25] * 4  # the true speed stays apart


def test_a_ride_on_an_env_of_its_own_begins_with_that_env_s_noise():
    env = UrbanDriveEnv(traffic_level=0.5, max_steps=3, obs_noise=(2.0, 0.6))
    session = RideSession(
        RideConfig(traffic_level=0.5, seed=3, max_steps=3), ScriptedController(),
        fake_language(), env=env,
    )  # fmt: skip
    try:
        session.start()
        assert session.controller.speed_noise_sd_mps == 0.6  # not the ride config's 0
    finally:
        session.close()


class OverriddenEveryThirdStep(ScriptedController):
    """Pretends the shield replaced a +3 m/s choice of the network every third step."""

    def __init__(self) -> None:
        super().__init__()
        self.use_shield = True
        self.steps = 0

    def act(self, obs):  # type: ignore[no-untyped-def]
        self.steps += 1
        self.last_override = self.steps % 3 == 0
        self.last_network_action = 6 if self.last_override else None
        return super().act(obs)


def test_the_event_log_says_when_the_shield_replaced_the_network():
    cfg = RideConfig(traffic_level=0.5, seed=3, max_steps=9)
    session = RideSession(cfg, OverriddenEveryThirdStep(), fake_language())
    session.start()
    while not session.done:
        session.step()
    session.close()  # libsumo runs one simulation per process: later tests need it free
    shields = [r.to_json()["shield"] for r in session.records]
    assert shields == [None, None, {"replaced": True, "network_action": 3}] * 3
    assert session.summary()["shield_replacements"] == 3
