"""The web app over the scripted driver and fake language modules, as its own process.

``python -m tests.web.serve_fakes PORT`` (from the repository root) serves it on
127.0.0.1 with the default limits, so that tests can measure the server process alone.
"""

from __future__ import annotations

import sys

import uvicorn

from explaindrive.web import create_app

from .conftest import fake_session_factory

STEP_PERIOD_S = 0.05  # [s]


def main() -> None:
    """Serve until killed."""
    port = int(sys.argv[1])
    app = create_app(fake_session_factory, step_period_s=STEP_PERIOD_S)
    uvicorn.run(app, host="127.0.0.1", port=port, log_level="warning")


if __name__ == "__main__":
    main()
