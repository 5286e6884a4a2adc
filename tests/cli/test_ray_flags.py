"""--ray without Ray installed: one line naming the extra."""

from __future__ import annotations

import importlib.util

import pytest
from typer.testing import CliRunner

from explaindrive.cli.app import app


@pytest.mark.parametrize(
    "args",
    [
        ["train", "--mode", "fast", "--ray"],
        ["evaluate", "fast", "--seeds", "0", "--ray-address", "127.0.0.1:1"],
        ["report", "--ray"],
    ],
)
def test_ray_flags_without_ray_name_the_extra(monkeypatch: pytest.MonkeyPatch, args) -> None:  # type: ignore[no-untyped-def]
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "ray" else real(name, *a)
    )
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert (
        " ".join(result.output.split())
        == "error: Ray is not installed: pip install 'explaindrive[ray]'"
    )
    assert "Traceback" not in result.output
