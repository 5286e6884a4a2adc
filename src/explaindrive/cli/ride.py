"""``explaindrive ride``: the passenger ride, the project's main job.

Bad settings, a bad script and an ``--out`` that cannot take the ride are refused with
one line and exit status 2 before anything loads. The ride is written into a staging
folder beside ``--out`` and moved into it at the end, so the previous ride there is
replaced only by a ride with a record of its own. Ctrl+C (SIGINT) or SIGTERM while the
models load ends the command at once and leaves ``--out`` as it was; while the car drives
it ends the ride after the current step (further signals change nothing): the steps
driven, the figure and a summary marked ``interrupted`` with the signal's name are
written, and the exit status is 128 + the signal's number (130, 143). A ride that stops
on an error writes the same and exits with status 1.
"""

from __future__ import annotations

import dataclasses
import functools
import queue
import signal
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Annotated, Any, NoReturn

import typer
from rich.console import Console
from rich.live import Live

from explaindrive.cli import _scenario_options as where
from explaindrive.cli._errors import print_error, refuse
from explaindrive.cli._grid_options import ComfortPolicyOption, FastPolicyOption, obs_noise_sd
from explaindrive.cli._language_common import read_config
from explaindrive.cli._signals import HANDLED_SIGNALS, exit_status, handle_signals, signal_label
from explaindrive.limits import MAX_SEED
from explaindrive.redact import redact
from explaindrive.ride.config import RideConfig
from explaindrive.ride.inputs import PassengerInput, SpokenLine, TypedLine

if TYPE_CHECKING:
    from explaindrive.language.config import LanguageConfig
    from explaindrive.ride.runner import RideOutputs
    from explaindrive.ride.script import ScriptLine
    from explaindrive.ride.session import RideSession

console = Console()

DEFAULTS = RideConfig()
"""The ride settings' defaults, which the options' defaults are (one home: RideConfig)."""


# What the passenger says, and how requests are confirmed
ScriptOption = Annotated[
    Path | None, typer.Option("--script", help="Timed passenger lines (YAML/JSON).")
]
InteractiveOption = Annotated[
    bool, typer.Option("--interactive", help="Type requests during the ride.")
]
VoiceOption = Annotated[
    bool, typer.Option("--voice", help="With --interactive: speak from the microphone.")
]
AutoConfirmOption = Annotated[
    bool, typer.Option("--auto-confirm", help="Answer every question with yes.")
]
StopWithoutConfirmOption = Annotated[
    bool, typer.Option("--stop-without-confirm", help="Apply STOP requests without asking.")
]
# The language modules
BackendOption = Annotated[
    str | None,
    typer.Option("--backend", help="Language backend: embedded or openai (default: --config's)."),
]
LanguageConfigOption = Annotated[
    Path | None,
    typer.Option(
        "--config",
        help="YAML language config: backend, endpoint, model, key variable, timeouts. "
        "A local server: 'backend: openai' and 'openai: {base_url: "
        "http://127.0.0.1:8080/v1, model: smollm2, timeout_s: 3}', then "
        "explaindrive ride --config local.yaml (docs/language.md).",
    ),
]
ModelOption = Annotated[
    str | None,
    typer.Option("--model", help="Model name for the openai backend (replaces --config's)."),
]
CooldownOption = Annotated[float, typer.Option("--cooldown", help="Explanation cool-down [s].")]
DeadlinesOption = Annotated[
    str | None,
    typer.Option(
        "--deadlines",
        help="Wall-time budgets of LLM-1, LLM-2 and LLM-3 [s], INTERPRET,DECIDE,EXPLAIN "
        "(default: 4,4,4; a remote model's openai.timeout_s + 0.2 must fit each).",
    ),
]
# The simulation
TrafficOption = Annotated[float, typer.Option("--traffic", help="Traffic level (1.0 = 900 veh/h).")]
SeedOption = Annotated[int, typer.Option("--seed", min=0, max=MAX_SEED, help="Simulation seed.")]
MaxStepsOption = Annotated[int, typer.Option("--max-steps", help="Longest ride [s].")]
GuiOption = Annotated[bool, typer.Option("--gui", help="Show the ride in sumo-gui.")]
ObsNoiseOption = Annotated[
    str | None,
    typer.Option("--obs-noise", help="Sensor noise SD_M,SD_MPS on what the driver sees."),
]
RealtimeOption = Annotated[bool, typer.Option("--realtime", help="One step per second.")]
# What the ride leaves behind, and the terminal view
OutOption = Annotated[Path, typer.Option("--out", help="Output directory (empty or new).")]
ForceOption = Annotated[
    bool, typer.Option("--force", help="Replace the ride already in --out instead of refusing.")
]
LiveOption = Annotated[bool, typer.Option("--live/--no-live", help="Live terminal view.")]


def ride(
    script: ScriptOption = None,
    interactive: InteractiveOption = False,
    voice: VoiceOption = False,
    backend: BackendOption = None,
    traffic: TrafficOption = DEFAULTS.traffic_level,
    seed: SeedOption = DEFAULTS.seed,
    gui: GuiOption = DEFAULTS.gui,
    realtime: RealtimeOption = DEFAULTS.realtime,
    out: OutOption = Path("out/ride"),
    force: ForceOption = False,
    auto_confirm: AutoConfirmOption = DEFAULTS.auto_confirm,
    stop_without_confirm: StopWithoutConfirmOption = DEFAULTS.stop_without_confirm,
    max_steps: MaxStepsOption = DEFAULTS.max_steps,
    cooldown: CooldownOption = DEFAULTS.explanation_cooldown_s,
    deadlines: DeadlinesOption = None,
    live: LiveOption = True,
    fast_policy: FastPolicyOption = None,
    comfort_policy: ComfortPolicyOption = None,
    obs_noise: ObsNoiseOption = None,
    scenario: where.ScenarioOption = None,
    net: where.NetOption = None,
    route: where.RouteOption = None,
    demand: where.DemandOption = None,
    language: LanguageConfigOption = None,
    model: ModelOption = None,
) -> None:
    """Ride in the simulated car: ask for fast, comfort or stop; watch it drive and explain."""
    from explaindrive.ride.runner import OutputDirError, prepare_out_dir
    from explaindrive.ride.script import ScriptError, default_script_path

    if voice and not interactive:
        _refuse("--voice needs --interactive")
    try:
        language_config = read_config(language, model)
        config = RideConfig(
            traffic_level=traffic,
            seed=seed,
            max_steps=max_steps,
            backend=backend or language_config.backend,
            auto_confirm=auto_confirm,
            stop_without_confirm=stop_without_confirm,
            explanation_cooldown_s=cooldown,
            realtime=realtime or interactive,
            gui=gui,
            fast_policy=fast_policy,
            comfort_policy=comfort_policy,
            obs_noise=obs_noise_sd(obs_noise),
            **module_deadlines(deadlines),
            **where.scenario_fields(scenario, net, route, demand),
        )
        lines = _script_lines(script, interactive, max_steps)
        staging = prepare_out_dir(out, force)
    except (FileNotFoundError, ValueError, ScriptError, OutputDirError) as exc:
        _refuse(exc)
    session = _build_session(config, language_config, lines, speech=voice)
    typed = _passenger_input(voice) if interactive else None
    if script is None and not interactive:
        console.print(f"default ride script: {default_script_path()}")
    _drive_and_report(session, lines, staging, out, typed, live)


def module_deadlines(text: str | None) -> dict[str, Any]:
    """``--deadlines INTERPRET,DECIDE,EXPLAIN`` as ``RideConfig`` fields ({} when not given).

    Raises:
        ValueError: unless it is three numbers separated by commas.
    """
    if text is None:
        return {}
    parts = text.split(",")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) != 3:
        raise ValueError(f"--deadlines takes INTERPRET,DECIDE,EXPLAIN in s, got {text!r}")
    names = ("interpret_deadline_s", "decide_deadline_s", "explain_deadline_s")
    return dict(zip(names, values, strict=True))


def _drive_and_report(
    session: RideSession,
    lines: list[ScriptLine],
    staging: Path,
    out: Path,
    typed: queue.Queue[PassengerInput | str] | None,
    live: bool,
) -> None:
    """Drive the ride (:func:`_run`) and print its summary; exit with 128 + the signal's
    number if a signal ended it."""
    outputs = _run(session, lines, staging, out, typed, live)
    _print_summary(session, outputs)
    if outputs.interrupted is not None:
        _exit_interrupted(session, outputs)


def _script_lines(script: Path | None, interactive: bool, max_steps: int) -> list[ScriptLine]:
    """The timed passenger lines: ``script``, none for an interactive ride without one, else
    the default script.

    Raises:
        ScriptError: if the script cannot be read or holds a bad line.
    """
    from explaindrive.ride.script import default_script_path, load_script

    if interactive and script is None:
        return []
    return load_script(script or default_script_path(), max_time_s=float(max_steps))


def _exit_interrupted(session: RideSession, outputs: RideOutputs) -> NoReturn:
    """Say how the ride was interrupted and exit with status 128 + the signal's number."""
    console.print(
        f"the ride was {outputs.interrupted} after {len(session.records)} s; "
        f"{outputs.summary} marks it interrupted",
        soft_wrap=True,
        highlight=False,
    )
    raise typer.Exit(exit_status(outputs.signum or signal.SIGINT))


class _StartupInterrupted(BaseException):
    """A signal before the ride's first step (``BaseException``: no library code that
    catches ``Exception`` while the models load may swallow it)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _end_start_up_on_signals(command: Callable[..., None]) -> Callable[..., None]:
    """``command`` with SIGINT and SIGTERM ending it at once, ``--out`` unchanged, until
    :func:`_run` takes them over for the drive (the handlers before it return at the end)."""

    @functools.wraps(command)
    def run(**options: Any) -> None:
        def start_up(signum: int, frame: FrameType | None) -> None:
            raise _StartupInterrupted(signum)

        try:
            with handle_signals(start_up):
                command(**options)
        except _StartupInterrupted as exc:
            _exit_unchanged(exc.signum, options["out"])

    return run


def _exit_unchanged(signum: int, out: Path) -> NoReturn:
    """Say that a signal ended the command before the first step, and exit."""
    console.print(
        f"stopped by {signal_label(signum)} before the ride started; {out} is unchanged",
        soft_wrap=True,
        highlight=False,
    )
    raise typer.Exit(exit_status(signum))


def _refuse(message: object) -> NoReturn:
    """Print one error line on stderr and exit with status 2."""
    refuse(message)


def _build_session(
    config: RideConfig, language_config: LanguageConfig, lines: list[ScriptLine], speech: bool
) -> RideSession:
    """The controller and the language stack (loaded now), or one line and status 2."""
    from explaindrive.agent.checkpoint import CheckpointError
    from explaindrive.agent.controller import MergedController
    from explaindrive.language.stack import make_language_stack
    from explaindrive.ride.session import RideSession

    try:
        controller = MergedController.from_package(
            fast=config.fast_policy, comfort=config.comfort_policy
        )
        stack = make_language_stack(config.backend, language_config)
        language = stack.load(speech=speech or any(ln.audio for ln in lines))
        return RideSession(config, controller, language)
    except (FileNotFoundError, ValueError, CheckpointError) as exc:
        _refuse(exc)


def _run(
    session: RideSession,
    lines: list[ScriptLine],
    staging: Path,
    out: Path,
    typed: queue.Queue[PassengerInput | str] | None,
    live: bool,
) -> RideOutputs:
    """Run the ride into ``staging``, then move it into ``out`` if it drove at least one
    step. From here on a signal stops the ride after the current step (and later ones
    change nothing); an error ends in one line and status 1; a stop before the first step
    leaves ``out`` as it was."""
    from explaindrive.ride.runner import StopRequest, commit_ride, discard_ride, run_ride
    from explaindrive.ride.view import render

    stop = StopRequest()
    if threading.current_thread() is threading.main_thread():
        for sig in HANDLED_SIGNALS:  # the command's own handlers come back when it ends
            signal.signal(sig, lambda signum, _frame: stop.request(signum))
    try:
        if live and sys.stdout.isatty():
            with Live(render(session, None), console=console, refresh_per_second=8) as view:
                outputs = run_ride(
                    session,
                    lines,
                    staging,
                    typed=typed,
                    on_step=lambda rec: view.update(render(session, rec)),
                    stop=stop,
                )
        else:
            outputs = run_ride(session, lines, staging, typed=typed, stop=stop)
    except Exception as exc:
        kept = session.records and (staging / "summary.json").is_file()
        where = commit_ride(staging, out).summary if kept else None
        discard_ride(staging)
        print_error(
            redact(
                f"the ride stopped on an error after {len(session.records)} s "
                f"({type(exc).__name__}: {exc}); "
                + (f"{where} marks it interrupted" if where else f"{out} is unchanged")
            ),
        )
        raise typer.Exit(1) from None
    if not session.records:
        discard_ride(staging)
        _exit_unchanged(stop.signum, out)
    final = commit_ride(staging, out)
    return dataclasses.replace(
        outputs, events=final.events, summary=final.summary, figure=final.figure
    )


def _passenger_input(voice: bool) -> queue.Queue[PassengerInput | str]:
    """Start reading the passenger's typed (or, with ``voice``, spoken) requests in the
    background; returns the queue they arrive in."""
    typed: queue.Queue[PassengerInput | str] = queue.Queue()

    def read() -> None:
        from explaindrive.ride.microphone import MicrophoneUnavailableError, record

        for line in sys.stdin:
            if voice:
                try:
                    path = record()
                except MicrophoneUnavailableError as exc:
                    console.print(f"[yellow]{exc}[/yellow]; the typed text is used instead")
                    typed.put(TypedLine(line))
                    continue
                typed.put(SpokenLine(path))
            else:
                typed.put(TypedLine(line))

    if voice:
        console.print("press Enter to speak (4 s), or type a request")
    else:
        console.print("type a request (or yes/no to answer a question) and press Enter")
    threading.Thread(target=read, daemon=True, name="passenger-input").start()
    return typed


def _print_summary(session: RideSession, outputs: RideOutputs) -> None:
    m = session.metrics.result()
    c = session.counts
    console.print(
        f"ride over after {len(session.records)} s: mean speed {m.mean_speed_mps:.2f} m/s, "
        f"collisions {m.collisions}, red-light runs {m.red_light_runs}, "
        f"pedestrian-yield violations {m.ped_violations}, yield violations "
        f"{m.yield_violations}, speeding steps {m.speeding_steps}"
    )
    console.print(
        f"requests {c.requests}, questions {c.questions}, confirmed {c.confirmations}, "
        f"cancelled {c.cancellations}, explanations {c.explanations} "
        f"(suppressed repeats {c.suppressed_explanations}), fallbacks {c.fallbacks}, "
        f"late {c.late}"
    )
    for name, label in (("interpret", "LLM-1"), ("decide", "LLM-2"), ("explain", "LLM-3")):
        k = c.models[name]
        stale = f", stale {k.stale}" if name == "explain" else ""
        console.print(
            f"{label} ({session.language.backend}): used {k.used}, fell back {k.fallback}, "
            f"vetoed {k.vetoed}, late {k.late}{stale}"
        )
    console.print(
        f"events:  {outputs.events}\nsummary: {outputs.summary}\nfigure:  {outputs.figure}"
    )


def register(app: typer.Typer) -> None:
    """Add the command to the CLI."""
    app.command("ride")(_end_start_up_on_signals(ride))
