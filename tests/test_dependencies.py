"""The installed packages are the ones the project chose (``dependencies.allow``)."""

from __future__ import annotations

import re
import site
from importlib import metadata
from pathlib import Path

ALLOW_LIST = Path(__file__).resolve().parents[1] / "dependencies.allow"
BOOTSTRAP = frozenset({"pip", "setuptools", "wheel"})  # the venv's own installers


def normalize(name: str) -> str:
    """PEP 503 name normalisation."""
    return re.sub(r"[-_.]+", "-", name).lower()


def allowed() -> set[str]:
    lines = ALLOW_LIST.read_text(encoding="utf-8").splitlines()
    return {normalize(line) for line in lines if line.strip() and not line.startswith("#")}


def test_every_installed_package_is_on_the_allow_list() -> None:
    # the environment's site-packages only: Ray puts copies of psutil and colorama that it
    # carries inside its own package on sys.path when it is imported
    dists = metadata.distributions(path=site.getsitepackages())
    installed = {normalize(d.metadata["Name"]) for d in dists}
    unexpected = sorted(installed - allowed() - BOOTSTRAP)
    assert not unexpected, (
        f"installed but not in dependencies.allow: {', '.join(unexpected)}; "
        "if the project needs them, add them there (and say why in the commit)"
    )


def test_the_allow_list_holds_the_declared_dependencies() -> None:
    names = allowed()
    assert {"torch", "gymnasium", "eclipse-sumo", "faster-whisper", "ray", "pytest"} <= names
    assert not {n for n in names if n.startswith(("aait", "categorit"))}
