"""The package's Python API: names imported on first use, the env id registered cheaply."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import explaindrive
from explaindrive.extras import MissingExtraError


def run(code: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)


def test_import_loads_neither_torch_nor_gymnasium() -> None:
    done = run(
        "import sys, explaindrive\n"
        "print([m for m in ('torch', 'gymnasium', 'numpy', 'matplotlib') if m in sys.modules])"
    )
    assert done.stdout.strip() == "[]"


def test_the_env_id_is_registered_when_gymnasium_loads() -> None:
    done = run(
        "import explaindrive, gymnasium as gym\n"
        "spec = gym.spec(explaindrive.ENV_ID)\n"
        "print(spec.entry_point)"
    )
    assert done.stdout.strip() == "explaindrive.env.urban_drive:UrbanDriveEnv"


def test_the_names_are_the_defining_modules_objects() -> None:
    from explaindrive.agent.checkpoint import load_policy
    from explaindrive.agent.controller import MergedController
    from explaindrive.env.urban_drive import UrbanDriveEnv
    from explaindrive.ride.session import RideSession

    assert explaindrive.UrbanDriveEnv is UrbanDriveEnv
    assert explaindrive.load_policy is load_policy
    assert explaindrive.RideSession is RideSession
    assert explaindrive.MergedController is MergedController
    assert set(explaindrive.__all__) <= set(dir(explaindrive))


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="has no attribute 'Nope'"):
        _ = explaindrive.Nope  # type: ignore[attr-defined]


def test_a_name_of_a_missing_extra_says_which(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    (tmp_path / "needs_the_page.py").write_text("import fastapi\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(sys.modules, "fastapi", None)  # as in an install without [web]
    monkeypatch.setitem(explaindrive._LAZY, "create_app", "needs_the_page")
    with pytest.raises(MissingExtraError) as caught:
        _ = explaindrive.create_app  # type: ignore[attr-defined]
    assert str(caught.value) == (
        "explaindrive.create_app needs the web extra (fastapi is not installed): "
        "pip install 'explaindrive[web]'"
    )
