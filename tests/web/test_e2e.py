"""The passenger page in a real headless Chromium against a live server.

Uses the shipped policies and the embedded language layer when both are
available, the scripted driver and keyword language modules otherwise.
Set ``EXPLAINDRIVE_WEB_SCREENSHOT=docs/web.png`` to keep the screenshot.
"""

from __future__ import annotations

import os
import shutil
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from explaindrive.web import RealStack, create_app

from .conftest import fake_session_factory

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
]
STEP_PERIOD_S = 0.1  # [s] ten control steps per second of wall time

pytestmark = [
    pytest.mark.browser,
    pytest.mark.slow,
    pytest.mark.skipif(not CHROMIUM.exists(), reason="Debian chromium is not installed"),
]


def real_stack_available() -> bool:
    """Whether the shipped policies exist and the embedded language layer can be built."""
    try:
        from explaindrive.agent.controller import shipped_policy_path
        from explaindrive.language.stack import make_language_stack  # noqa: F401

        return all(shipped_policy_path(name).is_file() for name in ("fast", "comfort"))
    except (ImportError, FileNotFoundError, ValueError):
        return False


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture(scope="module")
def server() -> Iterator[tuple[str, str]]:
    import uvicorn

    real = real_stack_available()
    factory = RealStack("embedded") if real else fake_session_factory
    app = create_app(factory, step_period_s=STEP_PERIOD_S)
    port = _free_port()
    srv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=srv.run, name="web-e2e-server", daemon=True)
    thread.start()
    end = time.monotonic() + 20
    while not srv.started:
        assert time.monotonic() < end and thread.is_alive(), "the server did not start"
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}/", "real" if real else "fakes"
    srv.should_exit = True
    thread.join(15)


def test_hurry_confirm_fast_and_explanations(server, tmp_path):
    from playwright.sync_api import expect, sync_playwright

    url, stack = server
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1400, "height": 900})
            errors: list[str] = []
            page.on("pageerror", lambda exc: errors.append(str(exc)))
            page.goto(url)
            expect(page.get_by_test_id("status")).to_have_text("idle", timeout=10_000)
            page.get_by_test_id("traffic").select_option("1.0")
            page.get_by_test_id("seed").fill("1")
            page.get_by_test_id("start").click()
            expect(page.get_by_test_id("status")).to_have_class("status running", timeout=60_000)
            expect(page.get_by_test_id("command")).to_have_attribute("data-command", "comfort")

            page.get_by_test_id("say-input").fill("I'm in a hurry")
            page.get_by_test_id("say-send").click()
            expect(page.get_by_test_id("yes")).to_be_enabled(timeout=15_000)
            expect(page.get_by_test_id("question")).to_contain_text("faster")
            page.get_by_test_id("yes").click()
            expect(page.get_by_test_id("command")).to_have_attribute(
                "data-command", "fast", timeout=10_000
            )
            expect(page.get_by_test_id("yes")).to_be_disabled()
            expect(page.get_by_test_id("log")).to_contain_text("Command comfort → fast")
            # the speed gauge rises by 5 km/h above the lowest speed shown under fast
            page.wait_for_function(
                """() => {
                  const v = parseFloat(document.getElementById('speed').textContent);
                  window.lowest = Math.min(window.lowest ?? v, v);
                  return v >= window.lowest + 5;
                }""",
                polling=50,
                timeout=30_000,
            )
            bubbles = page.get_by_test_id("bubble")
            expect(bubbles.first).to_be_visible(timeout=40_000)
            assert bubbles.first.inner_text().strip()

            # the ego is drawn in blue at the centre of the road view
            blue = page.evaluate(
                """() => {
                  const c = document.getElementById('road');
                  const r = window.devicePixelRatio || 1;
                  const d = c.getContext('2d').getImageData(
                    c.width / 2 - 40 * r, c.height / 2 - 40 * r, 80 * r, 80 * r).data;
                  let n = 0;
                  for (let i = 0; i < d.length; i += 4)
                    if (d[i] < 60 && d[i + 1] > 90 && d[i + 1] < 130 && d[i + 2] > 200) n++;
                  return n;
                }"""
            )
            assert blue > 20, "the ego is not drawn"
            time.sleep(1.0)  # a little more history on the chart for the screenshot
            shot = tmp_path / "web.png"
            page.screenshot(path=str(shot), full_page=True)
            assert shot.stat().st_size > 20_000
            keep = os.environ.get("EXPLAINDRIVE_WEB_SCREENSHOT")
            if keep:
                shutil.copyfile(shot, keep)
            page.get_by_test_id("reset").click()
            expect(page.get_by_test_id("status")).to_have_class("status idle", timeout=10_000)
            expect(page.get_by_test_id("explanations")).to_contain_text("Explanations appear")
            assert errors == [], f"page errors ({stack} stack): {errors}"
        finally:
            browser.close()
