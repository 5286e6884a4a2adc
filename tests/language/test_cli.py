"""The language CLI commands, called through Typer's test runner."""

from __future__ import annotations

import json

import typer
from typer.testing import CliRunner

from explaindrive.cli import explain, interpret, score, transcribe

app = typer.Typer()
for mod in (interpret, explain, transcribe, score):
    mod.register(app)
runner = CliRunner()


def test_explain_json(tmp_path) -> None:  # type: ignore[no-untyped-def]
    case = tmp_path / "case.json"
    case.write_text(
        json.dumps(
            {
                "request": "comfort",
                "action": -3,
                "state": {
                    "v_ego": 9.0,
                    "v_lim": 13.9,
                    "d_lead": None,
                    "dv": None,
                    "d_tl": None,
                    "tl_state": None,
                    "d_cross": 14.0,
                },
            }
        )
    )
    res = runner.invoke(app, ["explain", "--case", str(case), "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["explain"] is True and out["factor"] == "pedestrian" and "14 m" in out["text"]
    assert (out["fallback"], out["errors"]) == (False, [])
    case.write_text("{oops")
    res = runner.invoke(app, ["explain", "--case", str(case)])
    assert res.exit_code == 2 and "not valid JSON" in res.output


def test_interpret_json_and_bad_backend(interpreter) -> None:  # type: ignore[no-untyped-def]
    res = runner.invoke(app, ["interpret", "Stop the car!", "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert 0.0 < out.pop("latency_s") < 1.0
    assert out == {
        "intent": "stop",
        "confirmation": "You want me to stop, is this correct?",
        "backend": "embedded",
        "fallback": False,
        "stop_lane": False,
        "rule": None,
        "overruled": False,
        "reading": "stop",
        "ask": None,
        "error": None,
    }
    res = runner.invoke(app, ["interpret", "Why are we slowing down?", "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert (out["intent"], out["reading"]) == (None, "why")  # a question, not a command
    # STOP most probable, short of its threshold: no command, the car asks
    res = runner.invoke(app, ["interpret", "Out.", "--json"])
    out = json.loads(res.stdout)
    assert (out["intent"], out["ask"]) == (None, "stop")
    assert out["confirmation"] == "You want me to stop, is this correct?"
    res = runner.invoke(app, ["interpret", "Out."])
    assert "none (asks whether to stop)" in res.output
    res = runner.invoke(app, ["interpret", "hi", "--backend", "gpt9"])
    assert res.exit_code == 2 and "unknown language backend" in res.output


def test_transcribe_and_interpret_audio(transcriber, speak, tmp_path) -> None:  # type: ignore[no-untyped-def]
    wav = speak("Please drive faster, I am late.", "fast")
    res = runner.invoke(app, ["transcribe", str(wav), "--json"])
    assert res.exit_code == 0, res.output
    assert "faster" in json.loads(res.stdout)["text"].lower()
    res = runner.invoke(app, ["interpret", "--audio", str(tmp_path / "missing.wav")])
    assert res.exit_code == 2 and "not found" in res.output


def test_score_decisions_writes_report(tmp_path) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "dec.json"
    res = runner.invoke(app, ["score", "decisions", "--json", str(out)])
    assert res.exit_code == 0, res.output
    report = json.loads(out.read_text())
    assert report["n"] >= 80 and report["accuracy"] == 1.0 and report["factor_accuracy"] == 1.0


def test_score_intents_small_file(tmp_path, interpreter) -> None:  # type: ignore[no-untyped-def]
    data = tmp_path / "c.csv"
    data.write_text("text,label\nPull over now,stop\nPlease speed up,fast\nPlay music,none\n")
    out = tmp_path / "r.json"
    res = runner.invoke(app, ["score", "intents", "--data", str(data), "--json", str(out)])
    assert res.exit_code == 0, res.output
    r = json.loads(out.read_text())
    assert r["n_commands"] == 2 and r["template_compliance"] == 1.0
    assert r["per_class"]["stop"]["recall"] == 1.0


def test_score_intents_on_a_split_sweeps_the_trust_in_a_remote_model(  # type: ignore[no-untyped-def]
    tmp_path, interpreter, openai_server
) -> None:
    data = tmp_path / "c.csv"
    data.write_text(
        "text,label,kind,split\n"
        "Please speed up,fast,direct,dev-1\n"
        "Go faster please,fast,direct,reserve\n"
        "Drive gently,comfort,direct,reserve\n"
        "Play some music,none,offtopic,reserve\n"
    )
    # a model that reads every line as comfort
    openai_server.script = [("ok", "You want me to drive more carefully, is this correct?")]
    config = tmp_path / "llm.yaml"
    config.write_text(f"openai: {{base_url: {openai_server.base_url!r}, timeout_s: 5}}\n")
    out = tmp_path / "r.json"
    args = ["score", "intents", "--data", str(data), "--split", "reserve", "--backend", "openai"]
    res = runner.invoke(app, [*args, "--config", str(config), "--json", str(out)])
    assert res.exit_code == 0, res.output
    r = json.loads(out.read_text())
    assert r["n"] == 3 and r["split"] == "reserve" and len(openai_server.requests) == 3
    sweep = {row["sure_p"]: row for row in r["trust_sweep"]}
    # trusting the embedded reading always: its readings, all right
    assert sweep[0.0]["accuracy"] == 1.0 and sweep[0.0]["none_rejection"] == 1.0
    # trusting the model over any reading: fast and the remark become comfort
    assert sweep[1.0]["accuracy"] == 0.5 and sweep[1.0]["none_rejection"] == 0.0
    assert "trust_embedded_from" in res.output
    res = runner.invoke(app, ["score", "intents", "--data", str(data), "--split", "dev-2"])
    assert res.exit_code != 0 and "no rows of split 'dev-2'" in res.output


def test_score_intents_on_off_topic_lines_only_reports_their_figures(  # type: ignore[no-untyped-def]
    tmp_path, interpreter
) -> None:
    data = tmp_path / "offtopic.csv"
    data.write_text(
        "text,label\nWhat's the capital of Peru?,none\nI love this song.,none\n"
        "My laptop is so slow today.,none\n",
        encoding="utf-8",
    )
    out = tmp_path / "r.json"
    res = runner.invoke(app, ["score", "intents", "--data", str(data), "--json", str(out)])
    assert res.exit_code == 0, res.output
    assert "no command rows, off-topic figures only" in res.output
    report = json.loads(out.read_text())
    assert (report["n_commands"], report["n_none"], report["accuracy"]) == (0, 3, None)
    assert report["none_rejection"] == 1.0 and report["none_read_as_stop"] == 0


def test_score_everyday_counts_the_commands_given(tmp_path, interpreter) -> None:  # type: ignore[no-untyped-def]
    data = tmp_path / "talk.csv"
    data.write_text(
        "text,source\nHow was your weekend?,me\nPull over right now!,me\nNice shoes.,me\n"
        "Ha ha ha,me\n",
        encoding="utf-8",
    )
    out = tmp_path / "r.json"
    res = runner.invoke(app, ["score", "everyday", "--data", str(data), "--json", str(out)])
    assert res.exit_code == 0, res.output
    report = json.loads(out.read_text())
    assert report["n"] == 4 and report["commands"]["stop"] == 1
    assert report["left_without_command"] == 0.75  # 3 of 4
    assert report["given"] == [{"text": "Pull over right now!", "command": "stop"}]
    bad = tmp_path / "bad.csv"
    bad.write_text("words\nhello\n", encoding="utf-8")
    res = runner.invoke(app, ["score", "everyday", "--data", str(bad)])
    assert res.exit_code != 0 and "text column" in res.output
