"""A real-time ride against a model that answers well but slowly: is it heard?

Usage::

    python benchmarks/bench_slow_model.py [--delay 1.5] [--steps 120] [--seed 0]

Starts a local OpenAI-compatible endpoint that answers every call after ``--delay``
seconds as a good model would, and rides the default script in real time through the
``openai`` backend with the default deadlines (``RideConfig``, ``openai.timeout_s``):

* LLM-1: the confirmation question for a pace or stop request, else "not a request";
* LLM-2: ``[EXPLAIN]`` when the summary names a most urgent hazard or the passenger has been
  slowed or kept standing (the ride's history), else ``[NO EXPLANATION NEEDED]``;
* LLM-3: one sentence naming the most urgent hazard, else the first object of the summary,
  with its distance (no claim about the action).

Prints, per module, how often the model's own answer was used, fell back, was vetoed or
came late, and the share of the model's grounded explanations (used, not vetoed) that
reached the passenger (shown, not stale). Target (issue: "the model speaks in the ride"):
at least 90 % with a 1.5 s model. STOP's bound is checked by tests/ride/test_stop_lane.py.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import re
import tempfile
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

from explaindrive.agent.controller import MergedController
from explaindrive.language.backends.replies import NOT_A_REQUEST
from explaindrive.language.config import LanguageConfig, OpenAIConfig
from explaindrive.ride.config import RideConfig
from explaindrive.ride.runner import run_ride
from explaindrive.ride.script import default_script_path, load_script
from explaindrive.ride.session import RideSession

PACE = (
    (re.compile(r"\b(hurry|late|faster|quick)", re.I), "drive faster"),
    (re.compile(r"\b(stop|pull over|let me out)", re.I), "stop"),
    (re.compile(r"\b(gentl|slow|sick|careful)", re.I), "drive more carefully"),
)
URGENT = re.compile(r"Most urgent: the (.+?) \(")
OBJECTS = (
    re.compile(r"(Vehicle ahead) at (\d+) m"),
    re.compile(r"(Red|Yellow) traffic light in (\d+) m"),
    re.compile(r"(Pedestrian crossing the street) (\d+) m ahead"),
)


def good_reply(system: str, user: str) -> str:
    """What a good model says to one call of the ride (see the module docstring)."""
    if "reasoning module" in system:  # LLM-2
        noticed = "Most urgent:" in user or "under the limit" in user or "standing" in user
        return "[EXPLAIN]" if noticed else "[NO EXPLANATION NEEDED]"
    if "explain" in system.lower():  # LLM-3
        if m := URGENT.search(user):
            return f"It's for the {m.group(1)}; safety comes first."
        for pattern in OBJECTS:
            if m := pattern.search(user):
                what = m.group(1).lower().replace("vehicle ahead", "vehicle ahead of us")
                if "traffic light" in pattern.pattern:
                    what = f"{what} traffic light"
                return f"It's for the {what}, {m.group(2)} m away; safety comes first."
        return "Everything is fine, we're driving safely."
    if user.lower().startswith(("why", "what", "how")):  # LLM-1: a question, no request
        return NOT_A_REQUEST
    for pattern, action in PACE:  # LLM-1
        if pattern.search(user):
            return f"You want me to {action}, is this correct?"
    return NOT_A_REQUEST


class SlowGoodModel:
    """The endpoint, on 127.0.0.1 (a free port), served by a thread."""

    def __init__(self, delay_s: float) -> None:
        self.calls = 0

        outer = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: Any) -> None:
                pass

            def do_POST(self) -> None:
                body = json.loads(self.rfile.read(int(self.headers.get("Content-Length", "0"))))
                outer.calls += 1
                messages = {m["role"]: m["content"] for m in body["messages"]}
                text = good_reply(messages.get("system", ""), messages.get("user", ""))
                time.sleep(delay_s)
                reply = {
                    "id": "slow",
                    "object": "chat.completion",
                    "created": 0,
                    "model": "slow-good",
                    "choices": [
                        {
                            "index": 0,
                            "finish_reason": "stop",
                            "message": {"role": "assistant", "content": text},
                        }
                    ],
                }
                data = json.dumps(reply).encode()
                self.send_response(200)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                with contextlib.suppress(BrokenPipeError):
                    self.wfile.write(data)

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.server.daemon_threads = True
        self.base_url = f"http://127.0.0.1:{self.server.server_address[1]}/v1"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--delay", type=float, default=1.5, help="the model's answer time [s]")
    ap.add_argument("--steps", type=int, default=120, help="ride length [s of real time]")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    from explaindrive.language.stack import make_language_stack

    model = SlowGoodModel(args.delay)
    try:
        config = LanguageConfig(openai=OpenAIConfig(base_url=model.base_url, api_key="bench"))
        language = make_language_stack("openai", config).load()
        ride = RideConfig(max_steps=args.steps, backend="openai", realtime=True, seed=args.seed)
        session = RideSession(ride, MergedController.from_package(), language)
        script = [ln for ln in load_script(default_script_path()) if ln.t < args.steps]
        with tempfile.TemporaryDirectory() as out:
            run_ride(session, script, Path(out))
    finally:
        model.close()
    c = session.counts
    print(f"model answer time {args.delay:g} s, {model.calls} calls, ride {len(session.records)} s")
    for name, label in (("interpret", "LLM-1"), ("decide", "LLM-2"), ("explain", "LLM-3")):
        k = c.models[name]
        print(
            f"{label}: used {k.used}, fell back {k.fallback}, vetoed {k.vetoed}, "
            f"late {k.late}, stale {k.stale}"
        )
    grounded = [
        r.explanation
        for r in session.records
        if r.explanation is not None and r.explanation["backend"] == "openai"
    ]
    shown = [e for e in grounded if e.get("shown", True)]
    late = c.models["explain"].late
    total = len(grounded) + late
    share = len(shown) / total if total else float("nan")
    print(
        f"grounded model explanations that reached the passenger: {len(shown)} of {total} "
        f"({share:.0%}; target >= 90 %); questions answered {c.questions}"
    )


if __name__ == "__main__":
    main()
