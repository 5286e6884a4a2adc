"""Shared fixtures (a private cache for generated SUMO files, env construction) and the
``models`` marker: tests that load Whisper or the sentence encoder, which ``make test-fast``
leaves out with the ``slow`` and ``browser`` ones."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.language.backends import (
    Backend,
    LanguageModules,
    register_backend,
    unregister_backend,
)
from explaindrive.language.config import LanguageConfig

MODEL_FIXTURES = frozenset({"interpreter", "transcriber", "speak"})
MODEL_MODULES = frozenset({
    "tests/ride/test_ride_shipped.py", "tests/ride/test_stop_lane.py",
    "tests/language/test_cli.py", "tests/language/intent/test_shipped_models.py",
    "tests/language/intent/test_onnx_encoder.py", "tests/language/backends/test_openai.py",
    "tests/web/test_uploads.py", "tests/ride/test_ride_model_choice.py",
})  # fmt: skip


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark the tests that load a model (by their fixtures or their module)."""
    root = Path(str(config.rootpath))
    for item in items:
        module = Path(str(item.path)).relative_to(root).as_posix()
        if MODEL_FIXTURES & set(getattr(item, "fixturenames", ())) or module in MODEL_MODULES:
            item.add_marker(pytest.mark.models)


@pytest.fixture(scope="session", autouse=True)
def _private_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Keep generated demand files and warm-up states out of the user's cache."""
    old = os.environ.get("EXPLAINDRIVE_CACHE")
    os.environ["EXPLAINDRIVE_CACHE"] = str(tmp_path_factory.mktemp("explaindrive-cache"))
    yield
    if old is None:
        os.environ.pop("EXPLAINDRIVE_CACHE", None)
    else:
        os.environ["EXPLAINDRIVE_CACHE"] = old


@pytest.fixture
def make_env() -> Iterator[Callable[..., UrbanDriveEnv]]:
    """Build envs and close them all after the test (libsumo: one running at a time)."""
    made: list[UrbanDriveEnv] = []

    def factory(**kwargs: object) -> UrbanDriveEnv:
        for env in made:
            env.close()
        env = UrbanDriveEnv(**kwargs)  # type: ignore[arg-type]
        made.append(env)
        return env

    yield factory
    for env in made:
        env.close()


@pytest.fixture(scope="session")
def netgen(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., Path]:
    """Networks that SUMO's own ``netgenerate`` makes: ``netgen("grid", *options)``."""
    import subprocess

    from explaindrive.sim.sumo_home import sumo_binary

    made: dict[tuple[str, ...], Path] = {}

    def build(kind: str, *options: str) -> Path:
        key = (kind, *options)
        if key not in made:
            out = tmp_path_factory.mktemp("net") / f"{kind}.net.xml"
            args = [sumo_binary("netgenerate"), f"--{kind}", *options, "-o", str(out),
                    "--seed", "7", "--no-turnarounds", "true"]  # fmt: skip
            subprocess.run(args, check=True, capture_output=True)
            made[key] = out
        return made[key]

    return build


NO_DEMAND = "<routes>\n</routes>\n"
"""A demand file with no vehicle (a test adds its own)."""


def plain_net(folder: Path, name: str, nodes: str, edges: str, connections: str = "") -> Path:
    """``folder/name.net.xml``, built by netconvert from plain-XML nodes, edges and (if
    given) connections, without turnarounds."""
    import subprocess

    from explaindrive.sim.sumo_home import sumo_binary

    files = [("--node-files", "n.nod.xml", nodes), ("--edge-files", "e.edg.xml", edges)]
    if connections:
        files.append(("--connection-files", "c.con.xml", connections))
    args = [sumo_binary("netconvert"), "--no-turnarounds", "true"]
    for option, file_name, text in files:
        (folder / file_name).write_text(text)
        args += [option, str(folder / file_name)]
    out = folder / f"{name}.net.xml"
    subprocess.run([*args, "-o", str(out)], check=True, capture_output=True)
    return out


GRID_WITH_LIGHTS = ("--grid.number", "5", "--grid.length", "200",
                    "--default-junction-type", "traffic_light")  # fmt: skip
"""A 5x5 grid of 200 m blocks whose junctions all have lights."""


class FakeBackend(Backend):
    """A third language backend, as a plug-in would add one: keyword matching, a decider
    that explains braking, an explainer that echoes; no model and no network."""

    name = "fake"
    description = "keywords, no model"

    def build(self, config: LanguageConfig) -> LanguageModules:
        from tests.ride.fakes import BrakingDecider, EchoExplainer, KeywordInterpreter

        return LanguageModules(KeywordInterpreter(), BrakingDecider(), EchoExplainer())


@pytest.fixture
def fake_backend() -> Iterator[str]:
    """The ``fake`` backend registered for one test; yields its name."""
    register_backend(FakeBackend)
    yield FakeBackend.name
    unregister_backend(FakeBackend.name)
