"""``explaindrive ride``: the passenger ride, the project's main job.

Bad settings, a bad script and an ``--out`` that cannot take the ride are refused with
one line and exit status 2 before anything loads. Ctrl+C ends the ride after the
current step (a second Ctrl+C at once): the steps driven, the figure and a summary
marked ``interrupted`` are written, and the exit status is 130. A ride that stops on an
error writes the same and exits with status 1.
"""

from __future__ import annotations

import contextlib
import queue
import signal
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, NoReturn

import typer
from rich.console import Console
from rich.live import Live

from explaindrive.cli._errors import print_error
from explaindrive.cli._language_common import ENCODER_HELP
from explaindrive.language.config import LanguageConfig
from explaindrive.language.encoders import DEFAULT_ENCODER
from explaindrive.redact import redact
from explaindrive.ride.config import RideConfig
from explaindrive.ride.runner import OutputDirError, prepare_out_dir
from explaindrive.ride.script import (
    AUDIO_PREFIX,
    ScriptError,
    ScriptLine,
    default_script_path,
    load_script,
)

if TYPE_CHECKING:
    from explaindrive.ride.runner import RideOutputs
    from explaindrive.ride.session import RideSession

console = Console()
EXIT_INTERRUPTED = 130  # the shell's status for a command ended by Ctrl+C


def ride(
    script: Path = typer.Option(None, "--script", help="Timed passenger lines (YAML/JSON)."),
    interactive: bool = typer.Option(False, "--interactive", help="Type requests during the ride."),
    voice: bool = typer.Option(
        False, "--voice", help="With --interactive: speak from the microphone."
    ),
    backend: str = typer.Option(
        "embedded", "--backend", help="Language backend: embedded or openai."
    ),
    encoder: str = typer.Option(DEFAULT_ENCODER, "--encoder", help=ENCODER_HELP),
    traffic: float = typer.Option(1.0, "--traffic", help="Traffic level (1.0 = 900 veh/h)."),
    seed: int = typer.Option(0, "--seed", help="Simulation seed."),
    gui: bool = typer.Option(False, "--gui", help="Show the ride in sumo-gui."),
    realtime: bool = typer.Option(False, "--realtime", help="One step per second."),
    out: Path = typer.Option(Path("out/ride"), "--out", help="Output directory (empty or new)."),
    force: bool = typer.Option(
        False, "--force", help="Replace the ride already in --out instead of refusing."
    ),
    auto_confirm: bool = typer.Option(
        False, "--auto-confirm", help="Answer every question with yes."
    ),
    stop_without_confirm: bool = typer.Option(
        False, "--stop-without-confirm", help="Apply STOP requests without asking."
    ),
    max_steps: int = typer.Option(600, "--max-steps", help="Longest ride [s]."),
    cooldown: float = typer.Option(15.0, "--cooldown", help="Explanation cool-down [s]."),
    live: bool = typer.Option(True, "--live/--no-live", help="Live terminal view."),
) -> None:
    """Ride in the simulated car: ask for fast, comfort or stop; watch it drive and explain."""
    if voice and not interactive:
        _refuse("--voice needs --interactive")
    try:
        config = RideConfig(
            traffic_level=traffic,
            seed=seed,
            max_steps=max_steps,
            backend=backend,
            auto_confirm=auto_confirm,
            stop_without_confirm=stop_without_confirm,
            explanation_cooldown_s=cooldown,
            realtime=realtime or interactive,
            gui=gui,
        )
        language_config = LanguageConfig().with_encoder(encoder)
        lines = (
            []
            if interactive and script is None
            else load_script(script or default_script_path(), max_time_s=float(max_steps))
        )
        prepare_out_dir(out, force)
    except (ValueError, ScriptError, OutputDirError) as exc:
        _refuse(exc)
    session = _build_session(config, language_config, lines, speech=voice)
    typed: queue.Queue[str] | None = None
    if interactive:
        typed = queue.Queue()
        _start_input_thread(typed, voice)
    if script is None and not interactive:
        console.print(f"default ride script: {default_script_path()}")
    outputs = _run(session, lines, out, typed, live)
    _print_summary(session, outputs)
    if outputs.interrupted is not None:
        console.print(
            f"the ride was {outputs.interrupted} after {len(session.records)} s; "
            f"{outputs.summary} marks it interrupted",
            soft_wrap=True,
            highlight=False,
        )
        raise typer.Exit(EXIT_INTERRUPTED)


def _refuse(message: object) -> NoReturn:
    """Print one error line and exit with status 2."""
    print_error(console, message)
    raise typer.Exit(2)


def _build_session(
    config: RideConfig, language_config: LanguageConfig, lines: list[ScriptLine], speech: bool
) -> RideSession:
    """The controller and the language stack (loaded now), or one line and status 2."""
    from explaindrive.agent.checkpoint import CheckpointError
    from explaindrive.agent.controller import MergedController
    from explaindrive.language.stack import make_language_stack
    from explaindrive.ride.session import RideSession

    try:
        controller = MergedController.from_package()
        stack = make_language_stack(config.backend, language_config)
        language = stack.load(speech=speech or any(ln.audio for ln in lines))
        return RideSession(config, controller, language)
    except (FileNotFoundError, ValueError, CheckpointError) as exc:
        _refuse(exc)


def _run(
    session: RideSession,
    lines: list[ScriptLine],
    out: Path,
    typed: queue.Queue[str] | None,
    live: bool,
) -> RideOutputs:
    """Run the ride with Ctrl+C handled; an error ends in one line and status 1."""
    from explaindrive.ride.runner import run_ride
    from explaindrive.ride.view import render

    stop = threading.Event()
    try:
        with _stop_on_signals(stop):
            if live and sys.stdout.isatty():
                with Live(render(session, None), console=console, refresh_per_second=8) as view:
                    return run_ride(
                        session,
                        lines,
                        out,
                        typed=typed,
                        on_step=lambda rec: view.update(render(session, rec)),
                        stop=stop,
                    )
            return run_ride(session, lines, out, typed=typed, stop=stop)
    except Exception as exc:
        print_error(
            console,
            redact(
                f"the ride stopped on an error after {len(session.records)} s "
                f"({type(exc).__name__}: {exc}); {out / 'summary.json'} marks it interrupted"
            ),
        )
        raise typer.Exit(1) from exc


@contextlib.contextmanager
def _stop_on_signals(stop: threading.Event) -> Iterator[None]:
    """Ctrl+C (or SIGTERM) sets ``stop``; a second Ctrl+C raises ``KeyboardInterrupt``.

    Outside the main thread (where signal handlers cannot be set) nothing changes.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum: int, frame: FrameType | None) -> None:
        if stop.is_set() and signum == signal.SIGINT:
            raise KeyboardInterrupt
        stop.set()

    previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def _start_input_thread(typed: queue.Queue[str], voice: bool) -> None:
    def read() -> None:
        from explaindrive.ride.microphone import MicrophoneUnavailableError, record

        for line in sys.stdin:
            if voice:
                try:
                    path = record()
                except MicrophoneUnavailableError as exc:
                    console.print(f"[yellow]{exc}[/yellow]; the typed text is used instead")
                    typed.put(line)
                    continue
                typed.put(f"{AUDIO_PREFIX}{path}")
            else:
                typed.put(line)

    if voice:
        console.print("press Enter to speak (4 s), or type a request")
    else:
        console.print("type a request (or yes/no to answer a question) and press Enter")
    threading.Thread(target=read, daemon=True, name="passenger-input").start()


def _print_summary(session: RideSession, outputs: RideOutputs) -> None:
    m = session.metrics.result()
    c = session.counts
    console.print(
        f"ride over after {len(session.records)} s: mean speed {m.mean_speed_mps:.2f} m/s, "
        f"collisions {m.collisions}, red-light runs {m.red_light_runs}, "
        f"pedestrian-yield violations {m.ped_violations}, speeding steps {m.speeding_steps}"
    )
    console.print(
        f"requests {c.requests}, confirmed {c.confirmations}, cancelled {c.cancellations}, "
        f"explanations {c.explanations} (suppressed repeats {c.suppressed_explanations}), "
        f"fallbacks {c.fallbacks}, late {c.late}"
    )
    console.print(
        f"events:  {outputs.events}\nsummary: {outputs.summary}\nfigure:  {outputs.figure}"
    )


def register(app: typer.Typer) -> None:
    """Add the command to the CLI."""
    app.command("ride")(ride)
