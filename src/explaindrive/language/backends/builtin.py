"""The backends that ship with the package: ``embedded`` (offline) and ``openai``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from explaindrive.language.backends.registry import Backend, LanguageModules, register_backend

if TYPE_CHECKING:
    from explaindrive.language.config import LanguageConfig


@register_backend
class EmbeddedBackend(Backend):
    """Offline: sentence embeddings and the shipped classifier, a rule engine, templates."""

    name = "embedded"
    description = "offline: shipped classifier, rule engine, templates"

    def build(self, config: LanguageConfig) -> LanguageModules:
        """The embedded interpreter, decider and explainer."""
        from explaindrive.language.backends.embedded import (
            EmbeddedIntentInterpreter,
            RuleDecider,
            TemplateExplainer,
        )

        return LanguageModules(
            EmbeddedIntentInterpreter(config.embedded),
            RuleDecider(config.embedded),
            TemplateExplainer(config.embedded),
        )


@register_backend
class OpenAIBackend(Backend):
    """Any OpenAI-compatible chat endpoint, the embedded modules answering when it fails."""

    name = "openai"
    description = "an OpenAI-compatible endpoint, embedded fallback"
    remote = True

    def build(self, config: LanguageConfig) -> LanguageModules:
        """The remote modules, each wrapping its embedded fallback."""
        from explaindrive.language.backends.embedded import (
            EmbeddedIntentInterpreter,
            RuleDecider,
            TemplateExplainer,
        )
        from explaindrive.language.backends.openai import (
            ChatClient,
            OpenAIDecider,
            OpenAIExplainer,
            OpenAIIntentInterpreter,
        )

        client = ChatClient(config.openai)
        return LanguageModules(
            OpenAIIntentInterpreter(client, EmbeddedIntentInterpreter(config.embedded)),
            OpenAIDecider(client, RuleDecider(config.embedded)),
            OpenAIExplainer(client, TemplateExplainer(config.embedded)),
            remote_deadline_s=config.openai.timeout_s,
        )
