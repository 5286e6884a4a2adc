"""``explaindrive score intents|everyday|decisions``: score LLM-1 on labelled requests and
on everyday talk, LLM-2/LLM-3 on labelled state records."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer
from rich.table import Table

from explaindrive.cli._language_common import (
    BACKEND_HELP,
    CONFIG_HELP,
    MODEL_HELP,
    console,
    fail,
    load_config,
)
from explaindrive.cli._paths import refuse_bad_outputs
from explaindrive.language.data import DECISIONS_JSONL, EVERYDAY_CHECK, HELDOUT_CSV

score_app = typer.Typer(
    name="score",
    help="Score the language layer on labelled data.",
    no_args_is_help=True,
    add_completion=False,
)
T = TypeVar("T")
SHIPPED_COMMANDS = f"the shipped test split {HELDOUT_CSV}"
SHIPPED_EVERYDAY = f"the shipped external check {EVERYDAY_CHECK}"
SHIPPED_DECISIONS = f"the shipped {DECISIONS_JSONL}"


def _write(out: Path | None, data: dict[str, Any]) -> None:
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(data, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
        console.print(f"[dim]wrote {out}[/]")


def intents_command(
    data: Annotated[
        Path | None,
        typer.Option(
            "--data", help="CSV text,label[,kind][,split].", show_default=SHIPPED_COMMANDS
        ),
    ] = None,
    split: Annotated[
        str | None,
        typer.Option(
            "--split",
            help="Score only the rows of this split (column split), e.g. reserve in "
            "commands_train.csv, the split to choose a model's trust_embedded_from on.",
        ),
    ] = None,
    backend: Annotated[str | None, typer.Option("--backend", help=BACKEND_HELP)] = None,
    out: Annotated[Path | None, typer.Option("--json", help="Write the report here.")] = None,
    config: Annotated[Path | None, typer.Option("--config", help=CONFIG_HELP)] = None,
    model: Annotated[str | None, typer.Option("--model", help=MODEL_HELP)] = None,
) -> None:
    """Accuracy, macro-F1, kappa, template compliance and per-class figures of LLM-1; with a
    remote model, also the figures each trust_embedded_from would give on its replies."""
    from explaindrive.language.data import data_path
    from explaindrive.language.intent.datasets import load_commands

    refuse_bad_outputs(files=((out, "--json"),))
    data = data or data_path(HELDOUT_CSV)
    where = data.name if split is None else f"{data.name}, split {split}"
    rows, stack = _read_and_load(
        lambda: [r for r in load_commands(data) if split is None or r.split == split],
        f"{data}: no rows" + ("" if split is None else f" of split {split!r}"),
        (backend, config, model),
    )
    from explaindrive.language.evaluation import evaluate_intents

    report = evaluate_intents(stack.interpreter, rows)
    report.update(backend=stack.backend, data=str(data), split=split)
    _print_intents(report, f"LLM-1 on {where} ({stack.backend})")
    _write(out, report)


def _print_intents(report: dict[str, Any], title: str) -> None:
    """The per-class table, the summary line, the replies and the trust sweep."""
    if report["per_class"]:
        table = Table(title=title)
        for col in ("class", "precision", "recall", "F1", "support"):
            table.add_column(col, justify="right")
        for name, m in report["per_class"].items():
            table.add_row(
                name,
                f"{m['precision']:.3f}",
                f"{m['recall']:.3f}",
                f"{m['f1']:.3f}",
                str(m["support"]),
            )
        console.print(table)
    else:
        console.print(f"{title}: no command rows, off-topic figures only")
    console.print(
        f"accuracy {_fmt(report['accuracy'])}  macro-F1 {_fmt(report['macro_f1'])}  "
        f"kappa {_fmt(report['cohen_kappa'])}  template {_fmt(report['template_compliance'])}  "
        f"none rejected {_fmt(report['none_rejection'])} (read as STOP "
        f"{report['none_read_as_stop']})  (n={report['n_commands']} + {report['n_none']} "
        f"none; fallbacks {report['fallbacks']})",
        highlight=False,
    )
    replies = report["replies"]
    console.print(
        f"remote replies: accepted {replies['accepted']}, fell back {replies['fallback']}, "
        f"vetoed {replies['vetoed']}, not asked {replies['not_asked']}  "
        f"negated stops read as STOP {report['negated_stops_read_as_stop']}",
        highlight=False,
    )
    asked = report["asked_stop"]
    console.print(
        f"asked whether to stop: {sum(asked.values())} lines "
        f"({', '.join(f'{k} {v}' for k, v in sorted(asked.items())) or 'none'}); "
        f"STOP requests read as STOP or asked about {_fmt(report['stop_heard'])}",
        highlight=False,
    )
    if "trust_sweep" in report:
        sweep = Table(title="the same replies with another trust_embedded_from")
        for col in ("trust_embedded_from", "accuracy", "off-topic left", "STOP recall"):
            sweep.add_column(col, justify="right")
        for r in report["trust_sweep"]:
            sweep.add_row(
                f"{r['sure_p']:.2f}",
                *(_fmt(r[k]) for k in ("accuracy", "none_rejection", "stop_recall")),
            )
        console.print(sweep)


def everyday_command(
    data: Annotated[
        Path | None,
        typer.Option(
            "--data", help="CSV (or .csv.gz) with a text column.", show_default=SHIPPED_EVERYDAY
        ),
    ] = None,
    backend: Annotated[str | None, typer.Option("--backend", help=BACKEND_HELP)] = None,
    out: Annotated[Path | None, typer.Option("--json", help="Write the report here.")] = None,
    config: Annotated[Path | None, typer.Option("--config", help=CONFIG_HELP)] = None,
    model: Annotated[str | None, typer.Option("--model", help=MODEL_HELP)] = None,
) -> None:
    """LLM-1 on everyday lines that ask for nothing: the share left without a command and
    the commands given (the external check)."""
    from explaindrive.language.data import data_path
    from explaindrive.language.intent.corpus import read_lines

    refuse_bad_outputs(files=((out, "--json"),))
    data = data or data_path(EVERYDAY_CHECK)
    texts, stack = _read_and_load(
        lambda: [row["text"] for row in read_lines(data)],
        f"{data}: no rows",
        (backend, config, model),
    )
    from explaindrive.language.evaluation import evaluate_everyday

    report = evaluate_everyday(stack.interpreter, texts)
    report.update(backend=stack.backend, data=str(data))
    c = report["commands"]
    console.print(
        f"LLM-1 on {data.name} ({stack.backend}): {report['n']} lines, "
        f"{report['left_without_command']:.4f} left without a command; given fast "
        f"{c['fast']}, comfort {c['comfort']}, STOP {c['stop']}; asked whether to stop "
        f"{report['asked_stop']} ({report['left_alone']:.4f} left alone)",
        highlight=False,
    )
    for g in report["given"][:20]:
        console.print(f"  {g['command']:7s} {g['text'][:90]}", highlight=False)
    for g in report["asked"][:10]:
        console.print(f"  asked   {g['text'][:90]}", highlight=False)
    _write(out, report)


def _read_and_load(
    read: Callable[[], list[T]], empty: str, stack: tuple[str | None, Path | None, str | None]
) -> tuple[list[T], Any]:
    """The rows ``read`` returns and the language stack of ``stack`` (``--backend``,
    ``--config``, ``--model``: :func:`_stack`), loaded; a missing or bad file, no rows (the
    message ``empty``), a bad config or a backend that does not load ends the command with
    one line."""
    try:
        rows = read()
        if not rows:
            raise ValueError(empty)
        return rows, _stack(*stack).load()
    except (FileNotFoundError, ValueError) as exc:
        fail(str(exc))


def _stack(backend: str | None, config: Path | None, model: str | None) -> Any:
    """The language stack of ``--backend``, ``--config`` and ``--model`` (not loaded).

    Raises:
        FileNotFoundError, ValueError: for a bad config or backend.
    """
    from explaindrive.language.stack import make_language_stack

    return make_language_stack(backend, load_config(config, model))


def _fmt(x: float | None) -> str:
    return "-" if x is None else f"{x:.3f}"


def decisions_command(
    data: Annotated[
        Path | None,
        typer.Option("--data", help="JSONL of labelled records.", show_default=SHIPPED_DECISIONS),
    ] = None,
    backend: Annotated[str | None, typer.Option("--backend", help=BACKEND_HELP)] = None,
    out: Annotated[Path | None, typer.Option("--json", help="Write the report here.")] = None,
    config: Annotated[Path | None, typer.Option("--config", help=CONFIG_HELP)] = None,
    model: Annotated[str | None, typer.Option("--model", help=MODEL_HELP)] = None,
) -> None:
    """Trigger accuracy/precision/recall/F1, factor accuracy and checked explanations of
    LLM-2/LLM-3."""
    from explaindrive.language.data import data_path
    from explaindrive.language.explanation.datasets import load_decisions

    refuse_bad_outputs(files=((out, "--json"),))
    data = data or data_path(DECISIONS_JSONL)
    try:
        rows = load_decisions(data)
        stack = _stack(backend, config, model)
    except (FileNotFoundError, ValueError) as exc:
        fail(str(exc))
    from explaindrive.language.evaluation import evaluate_decisions

    report = evaluate_decisions(stack.decider, stack.explainer, rows)
    report.update(backend=stack.backend, data=str(data))
    console.print(
        f"decisions ({stack.backend}, n={report['n']}): accuracy {report['accuracy']:.3f}  "
        f"precision {report['precision']:.3f}  recall {report['recall']:.3f}  "
        f"F1 {report['f1']:.3f}  factor accuracy {report['factor_accuracy']} "
        f"(with several objects: {report['factor_accuracy_multi']}, n={report['n_multi']})  "
        f"grounded {report['grounded_share']}  true to the state {report['truthful_share']}  "
        f"fallbacks {report['fallbacks']}  vetoed {report['vetoed']}"
    )
    _write(out, report)


def register(app: typer.Typer) -> None:
    """Mount the ``score`` group (``intents``, ``everyday``, ``decisions``) on the root
    command."""
    score_app.command("intents")(intents_command)
    score_app.command("everyday")(everyday_command)
    score_app.command("decisions")(decisions_command)
    app.add_typer(score_app, name="score")
