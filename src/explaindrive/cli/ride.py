"""``explaindrive ride``: the passenger ride, the project's main job."""

from __future__ import annotations

import queue
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.console import Console
from rich.live import Live

from explaindrive.cli._errors import error_line
from explaindrive.cli._language_common import ENCODER_HELP
from explaindrive.language.encoders import DEFAULT_ENCODER
from explaindrive.ride.config import RideConfig
from explaindrive.ride.script import AUDIO_PREFIX, ScriptError, default_script_path, load_script

if TYPE_CHECKING:
    from explaindrive.ride.runner import RideOutputs
    from explaindrive.ride.session import RideSession

console = Console()


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
    out: Path = typer.Option(Path("out/ride"), "--out", help="Output directory."),
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
    from explaindrive.agent.checkpoint import CheckpointError
    from explaindrive.agent.controller import MergedController
    from explaindrive.language.config import LanguageConfig
    from explaindrive.language.stack import make_language_stack
    from explaindrive.ride.runner import run_ride
    from explaindrive.ride.session import RideSession
    from explaindrive.ride.view import render

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
        lines = (
            []
            if interactive and script is None
            else load_script(script or default_script_path(), max_time_s=float(max_steps))
        )
        controller = MergedController.from_package()
        language_config = LanguageConfig().with_encoder(encoder)
    except (ValueError, ScriptError, CheckpointError) as exc:
        console.print(error_line(exc))
        raise typer.Exit(2) from exc
    if voice and not interactive:
        console.print(error_line("--voice needs --interactive"))
        raise typer.Exit(2)
    typed: queue.Queue[str] | None = None
    if interactive:
        typed = queue.Queue()
        _start_input_thread(typed, voice)
    speech = voice or any(ln.audio for ln in lines)
    try:
        language = make_language_stack(backend, language_config).load(speech=speech)
    except (FileNotFoundError, ValueError) as exc:
        console.print(error_line(exc))
        raise typer.Exit(2) from exc
    session = RideSession(config, controller, language)
    if script is None and not interactive:
        console.print(f"default ride script: {default_script_path()}")
    if live and sys.stdout.isatty():
        with Live(render(session, None), console=console, refresh_per_second=8) as view:
            outputs = run_ride(
                session,
                lines,
                out,
                typed=typed,
                on_step=lambda rec: view.update(render(session, rec)),
            )
    else:
        outputs = run_ride(session, lines, out, typed=typed)
    _print_summary(session, outputs)


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
        f"ride over after {m.steps} s: mean speed {m.mean_speed_mps:.2f} m/s, "
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
