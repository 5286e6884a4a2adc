"""``explaindrive serve`` refuses bad names before a server starts."""

from __future__ import annotations

from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from explaindrive.cli import serve
from tests.helpers import constant_policy

app = typer.Typer()
serve.register(app)
app.command("noop")(lambda: None)  # two commands, so Typer keeps the sub-command name
runner = CliRunner()


def test_unknown_backend_exits_before_serving() -> None:
    res = runner.invoke(app, ["serve", "--backend", "gpt"])
    assert res.exit_code == 2
    assert "unknown language backend 'gpt'" in res.output


def test_the_served_names_reach_the_app(monkeypatch: pytest.MonkeyPatch) -> None:
    from explaindrive.web import server
    from explaindrive.web.guard import RequestGuard

    served: dict[str, object] = {}
    monkeypatch.setattr(
        server, "run_server", lambda app, host, port: served.update(app=app, host=host)
    )
    res = runner.invoke(app, ["serve", "--host", "0.0.0.0", "--allow-host", "Car.Local"])
    assert res.exit_code == 0, res.output
    assert "exposes the ride controls" in res.output and served["host"] == "0.0.0.0"
    (guard,) = [m for m in served["app"].user_middleware if m.cls is RequestGuard]  # type: ignore[attr-defined]
    assert guard.kwargs["hosts"] == {"127.0.0.1", "localhost", "::1", "car.local"}


def test_a_missing_policy_exits_before_serving(tmp_path: Path) -> None:
    res = runner.invoke(app, ["serve", "--fast-policy", str(tmp_path / "nope.pt")])
    assert res.exit_code == 2
    assert "policy file not found" in res.output


def test_a_trained_network_reaches_the_rides(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from explaindrive.web import server
    from explaindrive.web.app import RealStack

    run = tmp_path / "run"  # a training run directory
    run.mkdir()
    constant_policy(run / "policy.pt", 0, {"name": "mine"})
    served: dict[str, object] = {}
    monkeypatch.setattr(
        server, "run_server", lambda app, host, port: served.update(app=app, host=host)
    )
    res = runner.invoke(app, ["serve", "--fast-policy", str(run)])
    assert res.exit_code == 0, res.output
    stack = served["app"].state.manager.session_factory  # type: ignore[attr-defined]
    assert isinstance(stack, RealStack) and stack.policies == (run, None)


def test_the_configured_model_reaches_the_endpoint(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from explaindrive.language.explanation.summary import StateRecord
    from explaindrive.language.stack import make_language_stack
    from explaindrive.web import server as web_server
    from explaindrive.web.app import RealStack
    from tests.language.conftest import ScriptedOpenAI

    server = ScriptedOpenAI()
    try:
        config = tmp_path / "local.yaml"
        config.write_text(f"backend: openai\nopenai: {{base_url: {server.base_url}}}\n")
        served: dict[str, object] = {}
        monkeypatch.setattr(
            web_server, "run_server", lambda app, host, port: served.update(app=app, host=host)
        )
        res = runner.invoke(app, ["serve", "--config", str(config), "--model", "smollm2"])
        assert res.exit_code == 0, res.output
        stack = served["app"].state.manager.session_factory  # type: ignore[attr-defined]
        assert isinstance(stack, RealStack) and stack.backend == "openai"
        language = make_language_stack(stack.backend, stack.language_config)
        rec = StateRecord.model_validate(
            {"request": "fast", "action": -2, "state": {"v_ego": 9.0, "v_lim": 13.9}}
        )
        language.decider.decide(rec)
        assert [b["model"] for b in server.requests] == ["smollm2"]
    finally:
        server.close()


def test_a_missing_language_config_exits_before_serving(tmp_path: Path) -> None:
    res = runner.invoke(app, ["serve", "--config", str(tmp_path / "none.yaml")])
    assert res.exit_code == 2 and "language config not found" in res.output


def test_an_own_network_reaches_the_rides_and_the_page(
    monkeypatch: pytest.MonkeyPatch, netgen
) -> None:
    from explaindrive.web import server
    from explaindrive.web.app import RealStack
    from tests.conftest import GRID_WITH_LIGHTS

    net = netgen("grid", *GRID_WITH_LIGHTS)
    served: dict[str, object] = {}
    monkeypatch.setattr(
        server, "run_server", lambda app, host, port: served.update(app=app, host=host)
    )
    res = runner.invoke(app, ["serve", "--net", str(net), "--route", "A1B1,D1E1"])
    assert res.exit_code == 0, res.output
    web_app = served["app"]
    stack = web_app.state.manager.session_factory  # type: ignore[attr-defined]
    assert isinstance(stack, RealStack)
    assert stack.scenario["route"] == ("A1B1", "D1E1")
    assert Path(stack.scenario["net_file"]) == net
    bounds = web_app.state.scene.bounds  # type: ignore[attr-defined]
    assert bounds[2] - bounds[0] == 800.0  # the page draws the 5 x 5 grid, not the paper's road
