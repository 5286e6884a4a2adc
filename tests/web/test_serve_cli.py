"""``explaindrive serve`` refuses bad names before a server starts."""

from __future__ import annotations

import pytest
import typer
from typer.testing import CliRunner

from explaindrive.cli import serve

app = typer.Typer()
serve.register(app)
app.command("noop")(lambda: None)  # two commands, so Typer keeps the sub-command name
runner = CliRunner()


def test_unknown_backend_exits_before_serving() -> None:
    res = runner.invoke(app, ["serve", "--backend", "gpt"])
    assert res.exit_code == 2
    assert "unknown language backend 'gpt'" in res.output


def test_the_served_names_reach_the_app(monkeypatch: pytest.MonkeyPatch) -> None:
    import uvicorn

    from explaindrive.web.guard import RequestGuard

    served: dict[str, object] = {}
    monkeypatch.setattr(uvicorn, "run", lambda app, **kw: served.update(app=app, **kw))
    res = runner.invoke(app, ["serve", "--host", "0.0.0.0", "--allow-host", "Car.Local"])
    assert res.exit_code == 0, res.output
    assert "exposes the ride controls" in res.output and served["host"] == "0.0.0.0"
    (guard,) = [m for m in served["app"].user_middleware if m.cls is RequestGuard]  # type: ignore[attr-defined]
    assert guard.kwargs["hosts"] == {"127.0.0.1", "localhost", "::1", "car.local"}
