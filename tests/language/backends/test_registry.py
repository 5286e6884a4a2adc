"""A backend joins the registry without any edit to the stack; unknown names are one error."""

from __future__ import annotations

import pytest

from explaindrive.language.backends import (
    Backend,
    LanguageModules,
    UnknownBackendError,
    backend_names,
    get_backend,
    register_backend,
)
from explaindrive.language.config import LanguageConfig
from explaindrive.language.stack import make_language_stack
from explaindrive.ride.config import RideConfig
from tests.ride.fakes import BrakingDecider, EchoExplainer, KeywordInterpreter


def test_the_shipped_backends_and_their_capabilities() -> None:
    assert backend_names()[:2] == ("embedded", "openai")
    assert (get_backend("embedded").remote, get_backend("openai").remote) == (False, True)


def test_a_registered_backend_builds_the_stack(fake_backend: str) -> None:
    assert fake_backend in backend_names()
    stack = make_language_stack(fake_backend)
    assert stack.backend == "fake" and stack.remote_deadline_s is None
    assert isinstance(stack.interpreter, KeywordInterpreter)
    assert isinstance(stack.decider, BrakingDecider)
    assert isinstance(stack.explainer, EchoExplainer)
    assert stack.interpreter.interpret("please hurry").intent is not None


def test_configs_take_a_registered_backend(fake_backend: str) -> None:
    assert LanguageConfig(backend=fake_backend).backend == "fake"
    assert RideConfig(backend=fake_backend).backend == "fake"


def test_an_unknown_name_is_one_error_naming_the_known_ones(fake_backend: str) -> None:
    with pytest.raises(UnknownBackendError) as info:
        get_backend("gpt")
    assert str(info.value) == (
        "unknown language backend 'gpt'; choose one of: embedded, openai, fake"
    )
    with pytest.raises(ValueError, match="unknown language backend 'gpt'"):
        make_language_stack("gpt")


def test_a_name_is_registered_once(fake_backend: str) -> None:
    class Another(Backend):
        name = "fake"

        def build(self, config: LanguageConfig) -> LanguageModules:
            raise NotImplementedError

    with pytest.raises(ValueError, match="'fake' is already registered"):
        register_backend(Another)
    assert get_backend("fake").description == "keywords, no model"
