"""The registry of language backends: a backend joins it without any edit to the stack.

A backend is a small :class:`Backend` subclass with a ``name``, its capabilities as class
attributes, and :meth:`Backend.build`, which returns the three modules the ride calls
(LLM-1, LLM-2, LLM-3). :func:`register_backend` adds it (use it as a class decorator);
the stack, the configs and the commands then take its name. An unknown name is one
error naming the known ones. This module imports no model code: a backend imports its
own in :meth:`~Backend.build`.

Nor does it import the language config: the config checks its ``backend`` against this
registry (:func:`check_backend`), so the registry stays below it and
:meth:`Backend.build` takes the config untyped here (a backend annotates it as
:class:`~explaindrive.language.config.LanguageConfig`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, TypeVar

if TYPE_CHECKING:
    from explaindrive.language.explanation.decision import ExplanationDecider
    from explaindrive.language.explanation.explainer import Explainer
    from explaindrive.language.intent.interpreter import IntentInterpreter


class UnknownBackendError(ValueError):
    """No backend of that name is registered."""


@dataclass(frozen=True)
class LanguageModules:
    """What a backend builds: the modules the ride loop calls.

    Attributes:
        interpreter: LLM-1, a passenger request to a command.
        decider: LLM-2, whether a step needs an explanation.
        explainer: LLM-3, the explanation.
        remote_deadline_s: the total deadline of one call to a remote model [s], after
            which the embedded module answers; ``None`` when nothing remote is called.
    """

    interpreter: IntentInterpreter
    decider: ExplanationDecider
    explainer: Explainer
    remote_deadline_s: float | None = None


class Backend(ABC):
    """A language backend."""

    name: ClassVar[str]
    """The name configs and ``--backend`` use."""
    description: ClassVar[str] = ""
    """One line for listings."""
    remote: ClassVar[bool] = False
    """Capability: calls a model over the network (with a deadline, after which the
    embedded module answers); a ride checks the deadline against its own."""

    @abstractmethod
    def build(self, config: Any) -> LanguageModules:
        """The backend's modules, configured by ``config``, the layer's
        :class:`~explaindrive.language.config.LanguageConfig` (models load on first use)."""


B = TypeVar("B", bound=type[Backend])

_BACKENDS: dict[str, Backend] = {}


def register_backend(backend: B) -> B:
    """Add ``backend`` (a :class:`Backend` subclass) to the registry; returns it unchanged.

    Raises:
        ValueError: if its name is empty or already taken.
    """
    name = getattr(backend, "name", "")
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"{backend.__name__} needs a name to be registered")
    if name in _BACKENDS:
        raise ValueError(f"a language backend named {name!r} is already registered")
    _BACKENDS[name] = backend()
    return backend


def unregister_backend(name: str) -> None:
    """Remove the backend ``name`` (no error if there is none)."""
    _BACKENDS.pop(name, None)


def backend_names() -> tuple[str, ...]:
    """The registered backends' names, in the order they joined."""
    return tuple(_BACKENDS)


def get_backend(name: str) -> Backend:
    """The backend registered as ``name``.

    Raises:
        UnknownBackendError: naming the known backends.
    """
    try:
        return _BACKENDS[name]
    except (KeyError, TypeError):
        known = ", ".join(backend_names())
        raise UnknownBackendError(
            f"unknown language backend {name!r}; choose one of: {known}"
        ) from None


def check_backend(name: str) -> str:
    """Return ``name`` if a backend of that name is registered.

    Raises:
        UnknownBackendError: naming the known backends otherwise.
    """
    get_backend(name)
    return name
